//! Barometric height and magnetometer heading updates of the [`AidedNavigator`].
//!
//! Both arrive on their own topics, older than (or as old as) the IMU sample last propagated; the
//! filter applies them to its current state. A baro reading further from the navigation time than
//! `max_lag_s` is dropped rather than applied to the wrong epoch.

use crate::checks::positive;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::aided::AidedNavigator;
use crate::ekf::{AidingSource, POS, UpdateOutcome};
use crate::mag_heading::{FieldReference, adaptive_sigma, measured_heading};

/// Settings of the barometric height aiding (`[navigator.baro]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BaroAidingConfig {
    /// Apply baro height updates.
    pub enabled: bool,
    /// Smallest σ used, m, whatever variance the altimeter reports (its variance is that of the
    /// pressure noise; the ISA model and weather add errors it does not see).
    pub sigma_floor_m: f64,
    /// Innovation gate (Mahalanobis distance).
    pub gate: f64,
    /// Largest accepted |reading time − navigation time|, s.
    pub max_lag_s: f64,
}

impl Default for BaroAidingConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            sigma_floor_m: 0.5,
            gate: 5.0,
            max_lag_s: 0.1,
        }
    }
}

impl BaroAidingConfig {
    /// `(field, value)` of the first out-of-range parameter.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        positive("sigma_floor_m", self.sigma_floor_m)?;
        positive("gate", self.gate)?;
        positive("max_lag_s", self.max_lag_s)
    }
}

/// What became of one aiding reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AidingOutcome {
    /// The filter took it (accepted or gated out: see the outcome).
    Update(UpdateOutcome),
    /// Kept for later: before alignment (the first baro height, the alignment heading).
    Stored,
    /// The first reading after an outage: the state was re-set from it (baro) or it was applied
    /// without the innovation gate (mag).
    Readmitted,
    /// Not used: aiding disabled, a bad reading, too old, rate limit, outside stance for HUPT.
    Skipped,
}

impl AidedNavigator {
    /// One barometric height (m above mean sea level) with its variance (m²) at device time
    /// `t_us`. Before alignment the first valid reading becomes the starting altitude; the first
    /// reading after an alignment without one sets the altitude directly.
    pub fn on_baro(
        &mut self,
        t_us: u64,
        height_m: f64,
        variance_m2: f64,
        valid: bool,
    ) -> AidingOutcome {
        let c = self.config.baro;
        if !valid || !height_m.is_finite() {
            return AidingOutcome::Skipped;
        }
        let first = self.initial_height_m.is_none();
        if first {
            self.initial_height_m = Some(height_m);
        }
        // Back after an outage: the altitude has coasted on the accelerometers and the weather
        // may have moved the baro; the reading re-sets the altitude rather than face the gate.
        let returning = c.enabled && self.is_stale(AidingSource::Baro);
        self.last_reading_us[AidingSource::Baro as usize] = Some(t_us);
        let now_us = self.time_us();
        let Some(ekf) = self.ekf_mut() else {
            return AidingOutcome::Stored;
        };
        if first {
            ekf.state_mut().alt = height_m;
            return AidingOutcome::Stored;
        }
        if !c.enabled {
            return AidingOutcome::Skipped;
        }
        if returning {
            let variance = if variance_m2.is_finite() {
                variance_m2
            } else {
                0.0
            };
            ekf.state_mut().alt = height_m;
            ekf.reset_component(POS + 2, variance.max(c.sigma_floor_m * c.sigma_floor_m));
            self.last_accepted_us[AidingSource::Baro as usize] = Some(t_us);
            return AidingOutcome::Readmitted;
        }
        let lag_s = now_us.map_or(f64::INFINITY, |n| n.abs_diff(t_us) as f64 * 1e-6);
        if lag_s > c.max_lag_s {
            return AidingOutcome::Skipped;
        }
        let variance = if variance_m2.is_finite() {
            variance_m2
        } else {
            0.0
        };
        let sigma = variance.max(c.sigma_floor_m * c.sigma_floor_m).sqrt();
        let outcome = ekf.height(height_m, sigma, c.gate);
        if outcome.is_accepted() {
            self.last_accepted_us[AidingSource::Baro as usize] = Some(t_us);
        }
        AidingOutcome::Update(outcome)
    }

    /// One magnetometer sample (raw µT, body FRD) at device time `t_us`: calibrated, then used
    /// for the alignment heading, or as a heading update (only in stance, counted as HUPT, when
    /// `stance_only`).
    pub fn on_mag(&mut self, t_us: u64, raw_ut: [f64; 3]) -> AidingOutcome {
        if raw_ut.iter().any(|x| !x.is_finite()) {
            return AidingOutcome::Skipped;
        }
        let field = self.config.mag_calibration.apply(raw_ut);
        if let Some(aligner) = self.aligner_mut() {
            aligner.push_mag(t_us, field);
            return AidingOutcome::Stored;
        }
        let c = self.config.mag;
        if !c.enabled || (c.stance_only && !self.in_stance) {
            return AidingOutcome::Skipped;
        }
        // Back after an outage: the heading has coasted on the gyros; the first reading is
        // applied whatever its innovation, the following ones are gated again.
        let returning = self.is_stale(AidingSource::Mag);
        self.last_reading_us[AidingSource::Mag as usize] = Some(t_us);
        if c.max_rate_hz > 0.0
            && let Some(last) = self.last_mag_update_us
            && (t_us.saturating_sub(last) as f64) < 1e6 / c.max_rate_hz
        {
            return AidingOutcome::Skipped;
        }
        if self.field_reference.is_none()
            && self.reference_from_next_mag
            && let Some(ekf) = self.ekf()
        {
            let attitude = ekf.state().attitude;
            self.field_reference = FieldReference::from_field(&Vector3::from(field), &attitude);
            self.reference_from_next_mag = false;
        }
        let Some(reference) = self.field_reference else {
            return AidingOutcome::Skipped;
        };
        let (declination, force) = (self.config.declination_rad, self.last_force);
        let source = if c.stance_only {
            AidingSource::Hupt
        } else {
            AidingSource::Mag
        };
        let Some(ekf) = self.ekf_mut() else {
            return AidingOutcome::Skipped;
        };
        let field = Vector3::from(field);
        let attitude = ekf.state().attitude;
        let Some(psi) = measured_heading(&field, &attitude, declination) else {
            return AidingOutcome::Skipped;
        };
        let g = ekf.strapdown().gravity();
        let sigma = adaptive_sigma(&c, &reference, &force, g, &field, &attitude);
        let gate = if returning { f64::INFINITY } else { c.gate };
        let outcome = ekf.heading(source, psi, sigma, gate);
        self.last_mag_update_us = Some(t_us);
        if outcome.is_accepted() {
            self.last_accepted_us[source as usize] = Some(t_us);
        }
        if returning && outcome.is_accepted() {
            AidingOutcome::Readmitted
        } else {
            AidingOutcome::Update(outcome)
        }
    }
}
