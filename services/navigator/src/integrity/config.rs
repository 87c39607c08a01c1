//! The settings of the integrity monitor (`[navigator.integrity]`) and their ranges.

use serde::{Deserialize, Serialize};

/// Longest NIS window.
pub const MAX_NIS_WINDOW: usize = 64;

/// Settings of the integrity monitor (`[navigator.integrity]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IntegrityConfig {
    /// An IMU outage longer than this makes the solution invalid, s of device time.
    pub imu_outage_s: f64,
    /// IMU samples in a row whose device time does not advance (or jumps beyond `max_dt_s`)
    /// that make the solution invalid.
    pub time_stall_samples: u32,
    /// Accepted updates per aiding source in the NIS window, 1..=64.
    pub nis_window: u32,
    /// Mean of d²/m over the window above which a source is inconsistent.
    pub nis_limit: f64,
    /// A source whose every update is gated out for this long is persistently rejected, s.
    pub rejection_persist_s: f64,
    /// Reset the filter from a persistently rejected source (altitude from the baro, heading
    /// from an undisturbed magnetometer): the filter, not the sensor, is then taken to be wrong.
    pub reset_from_aiding: bool,
    /// Held degraded this long after an invalid episode or a reset, s.
    pub recovery_s: f64,
    /// Limits on the error standard deviations (0 = no limit): roll/pitch, heading (degrees),
    /// vertical and horizontal position (metres). Without horizontal aiding the horizontal error
    /// grows without bound by design: set a limit where the mission needs one.
    pub max_tilt_sigma_deg: f64,
    /// Limit on the heading error σ, degrees (0 = no limit).
    pub max_heading_sigma_deg: f64,
    /// Limit on the vertical position error σ, m (0 = no limit).
    pub max_vertical_sigma_m: f64,
    /// Limit on the horizontal position error σ, m (0 = no limit).
    pub max_horizontal_sigma_m: f64,
    /// After the IMU stopped propagating the state for an invalid spell, the attitude is lost:
    /// its error σ on every axis, degrees (see [`crate::attitude_recovery`]).
    pub lost_attitude_sigma_deg: f64,
    /// Re-levelling from gravity: window, s; σ of the window's mean specific force as a
    /// measurement of gravity, m/s²; the window counts as quasi-static when its mean |f| is
    /// within the tolerance of g (m/s²) and no rate exceeds the limit (°/s); re-levelling ends
    /// once the tilt σ is below `relevelled_tilt_sigma_deg`.
    pub gravity_window_s: f64,
    /// Re-levelling: σ of the window's mean specific force as a measurement of gravity, m/s².
    pub gravity_sigma_mps2: f64,
    /// Re-levelling: largest `| |f̄| − g |` of a quasi-static window, m/s².
    pub gravity_force_tolerance_mps2: f64,
    /// Re-levelling: largest rate in a quasi-static window, °/s.
    pub gravity_max_rate_dps: f64,
    /// Re-levelling ends once the tilt σ is below this, degrees.
    pub relevelled_tilt_sigma_deg: f64,
    /// After a fault fusion could not isolate at once, the integrity stays degraded until every
    /// attitude error σ is below this (or below its value when the fault was detected, if that
    /// was larger), degrees: the attitude σ was widened by the error the fault may have left. When
    /// that error bound itself exceeded this, the integrity stays degraded while the filter runs.
    pub fault_attitude_sigma_deg: f64,
}

impl Default for IntegrityConfig {
    fn default() -> Self {
        Self {
            imu_outage_s: 0.05,
            time_stall_samples: 10,
            nis_window: 20,
            nis_limit: 4.0,
            rejection_persist_s: 2.0,
            reset_from_aiding: true,
            recovery_s: 1.0,
            max_tilt_sigma_deg: 5.0,
            max_heading_sigma_deg: 30.0,
            max_vertical_sigma_m: 20.0,
            max_horizontal_sigma_m: 0.0,
            lost_attitude_sigma_deg: 45.0,
            gravity_window_s: 0.1,
            gravity_sigma_mps2: 0.1,
            gravity_force_tolerance_mps2: 0.3,
            gravity_max_rate_dps: 10.0,
            relevelled_tilt_sigma_deg: 0.3,
            fault_attitude_sigma_deg: 1.0,
        }
    }
}

impl IntegrityConfig {
    /// `(field, value)` of the first out-of-range parameter.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        let positive = |field, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err((field, v))
            }
        };
        let limit = |field, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err((field, v))
            }
        };
        positive("imu_outage_s", self.imu_outage_s)?;
        if self.time_stall_samples == 0 {
            return Err(("time_stall_samples", 0.0));
        }
        if !(1..=MAX_NIS_WINDOW as u32).contains(&self.nis_window) {
            return Err(("nis_window", f64::from(self.nis_window)));
        }
        positive("nis_limit", self.nis_limit)?;
        positive("rejection_persist_s", self.rejection_persist_s)?;
        limit("recovery_s", self.recovery_s)?;
        limit("max_tilt_sigma_deg", self.max_tilt_sigma_deg)?;
        limit("max_heading_sigma_deg", self.max_heading_sigma_deg)?;
        limit("max_vertical_sigma_m", self.max_vertical_sigma_m)?;
        limit("max_horizontal_sigma_m", self.max_horizontal_sigma_m)?;
        positive("lost_attitude_sigma_deg", self.lost_attitude_sigma_deg)?;
        positive("gravity_window_s", self.gravity_window_s)?;
        positive("gravity_sigma_mps2", self.gravity_sigma_mps2)?;
        positive(
            "gravity_force_tolerance_mps2",
            self.gravity_force_tolerance_mps2,
        )?;
        positive("gravity_max_rate_dps", self.gravity_max_rate_dps)?;
        positive("relevelled_tilt_sigma_deg", self.relevelled_tilt_sigma_deg)?;
        positive("fault_attitude_sigma_deg", self.fault_attitude_sigma_deg)
    }
}
