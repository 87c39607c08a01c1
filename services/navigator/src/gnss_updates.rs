//! GNSS position and velocity updates of the [`AidedNavigator`]: each fix compared with the
//! filter's state at the instant the receiver measured (see [`crate::state_history`]), judged by
//! the consistency monitor ([`crate::gnss_monitor`]), and applied when the receiver is believed.

use ipc_types::{GnssFix, GnssFixType};
use nalgebra::Vector3;

use crate::ekf::gnss::{Linearised, antenna_position, antenna_velocity};
use crate::ekf::{AidingSource, ErrorStateEkf, POS, UpdateOutcome};
use crate::gnss_monitor::Verdict;
use crate::inertial_core::AidedNavigator;
use crate::state_history::HistoryError;

/// One receiver fix, placed on the device time base.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssMeasurement {
    /// Device time of the instant the receiver measured, µs.
    pub t_us: u64,
    /// The receiver's own time of the fix, µs: a fix whose time does not advance is a repeat.
    pub receiver_time_us: u64,
    /// The receiver has a three-dimensional fix from the satellites.
    pub fix_3d: bool,
    /// Antenna latitude, longitude (rad) and altitude (m).
    pub position: [f64; 3],
    /// Antenna velocity NED, m/s, when reported.
    pub velocity_ned: Option<[f64; 3]>,
    /// Reported horizontal σ per axis, m.
    pub sigma_h_m: f64,
    /// Reported vertical σ, m.
    pub sigma_v_m: f64,
    /// Reported velocity σ per axis, m/s.
    pub sigma_vel_mps: f64,
}

impl GnssMeasurement {
    /// The measurement of `fix`, whose receiver measured at device time `t_us`.
    pub fn from_fix(fix: &GnssFix, t_us: u64) -> Self {
        let fix_3d = GnssFixType::from_u8(fix.fix_type).is_some_and(GnssFixType::is_3d);
        Self {
            t_us,
            receiver_time_us: fix.receiver_time_us,
            fix_3d,
            position: [fix.latitude_rad, fix.longitude_rad, fix.altitude_m],
            velocity_ned: (fix.velocity_valid != 0).then_some(fix.velocity_ned_mps),
            sigma_h_m: fix.horizontal_accuracy_m,
            sigma_v_m: fix.vertical_accuracy_m,
            sigma_vel_mps: fix.speed_accuracy_mps,
        }
    }

    fn is_finite(&self) -> bool {
        self.position.iter().all(|x| x.is_finite())
            && self
                .velocity_ned
                .is_none_or(|v| v.iter().all(|x| x.is_finite()))
    }
}

/// What became of one fix.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GnssOutcome {
    /// Position (and velocity) applied; `d2` is the position innovation's squared Mahalanobis
    /// distance.
    Applied {
        /// Squared Mahalanobis distance of the position innovation.
        d2: f64,
    },
    /// The receiver came back after a rejection; this fix was applied.
    Readmitted,
    /// Outside the gate, alone so far: skipped.
    Outlier,
    /// The receiver is judged inconsistent: skipped.
    Rejected,
    /// No three-dimensional fix, or values that are not numbers: nothing to apply.
    NoFix,
    /// The receiver's time did not advance (a frozen receiver repeating itself): skipped.
    Repeated,
    /// Measured before the oldest remembered state: skipped.
    TooOld,
    /// GNSS aiding is off, or the filter is not navigating yet.
    NotUsed,
}

impl AidedNavigator {
    /// One receiver fix (see [`GnssMeasurement`]).
    pub fn on_gnss(&mut self, m: &GnssMeasurement) -> GnssOutcome {
        let c = self.config.gnss;
        if !c.enabled || !self.is_navigating() {
            return GnssOutcome::NotUsed;
        }
        if !m.fix_3d || !m.is_finite() {
            return GnssOutcome::NoFix;
        }
        if self
            .gnss
            .last_receiver_time_us
            .is_some_and(|last| m.receiver_time_us <= last)
        {
            return GnssOutcome::Repeated;
        }
        self.gnss.last_receiver_time_us = Some(m.receiver_time_us);
        // Back after an outage: the position has coasted, its covariance grown and its
        // correlations with velocity and attitude stretched far beyond what one fix can sort out;
        // the fix re-sets the position (and velocity) instead of being gated against it.
        // Without a known position, the first fix sets it the same way: gated against a
        // placeholder, it would only ever be rejected.
        let returning = self.is_stale(AidingSource::Gnss) || self.integrity.position_unknown();
        self.last_reading_us[AidingSource::Gnss as usize] = Some(m.t_us);
        if returning && self.gnss.monitor.rejected().is_none() {
            return self.reset_from_fix(m);
        }
        let Some(ekf) = self.ekf() else {
            return GnssOutcome::NotUsed;
        };
        let past = match self.gnss.history.at(m.t_us, ekf.corrections()) {
            Ok(past) => past,
            Err(HistoryError::TooOld | HistoryError::Empty) => return GnssOutcome::TooOld,
        };
        let arm = Vector3::from(c.lever_arm_m);
        let position = antenna_position(
            &past,
            m.position,
            &arm,
            floor(m.sigma_h_m, c.sigma_horizontal_floor_m),
            floor(m.sigma_v_m, c.sigma_vertical_floor_m),
        );
        let Some((s, d2)) = ekf.innovation_test(&position.h, &position.innovation, &position.r)
        else {
            return GnssOutcome::Outlier;
        };
        let normalised = [0, 1].map(|k| position.innovation[k] / s[(k, k)].max(0.0).sqrt());
        // A rejected receiver stays out while its fixes are still at least half as far from the
        // solution as when it was rejected: the coast's growing covariance would in time make a
        // persistent jump look consistent, and a drift that goes on never leaves the gate at
        // all. A receiver that jumped back is judged by the covariance as it has grown, which
        // includes the coast's own drift.
        let offset_m = position.innovation.x.hypot(position.innovation.y);
        let d2 = match (self.gnss.monitor.rejected(), self.gnss.jump_offset_m) {
            (Some(_), Some(at_rejection)) if offset_m >= 0.5 * at_rejection => f64::INFINITY,
            _ => d2,
        };
        let mut verdict = self.gnss.monitor.judge(m.t_us, d2, normalised);
        if verdict == Verdict::Use {
            let sigma_h = floor(m.sigma_h_m, c.sigma_horizontal_floor_m);
            // The receiver's own velocity where it reports one (see `gnss_displacement` for why
            // not the solution's), the solution's otherwise.
            let velocity = m.velocity_ned.map_or(past.velocity_ned, Vector3::from);
            let displaced = self
                .gnss
                .displacement
                .push(m.t_us, m.position, &velocity, sigma_h);
            if displaced.is_some_and(|d| d > c.displacement_threshold) {
                self.gnss.monitor.reject_for_drift(m.t_us);
                verdict = Verdict::Rejected;
            }
        } else {
            self.gnss.displacement.reset();
        }
        if verdict == Verdict::Rejected && self.gnss.jump_offset_m.is_none() {
            self.gnss.jump_offset_m = Some(offset_m);
        }
        if verdict == Verdict::Readmitted {
            self.gnss.jump_offset_m = None;
        }
        match verdict {
            Verdict::Use => {}
            // Back after coasting: the fix re-sets the position as after an outage, for the
            // same reason (see `reset_from_fix`).
            Verdict::Readmitted => return self.reset_from_fix(m),
            Verdict::Outlier => return GnssOutcome::Outlier,
            Verdict::Rejected => return GnssOutcome::Rejected,
        }
        let velocity = m.velocity_ned.filter(|_| c.use_velocity).map(|v| {
            antenna_velocity(
                &past,
                v,
                &arm,
                floor(m.sigma_vel_mps, c.sigma_velocity_floor_mps),
            )
        });
        let Some(ekf) = self.ekf_mut() else {
            return GnssOutcome::NotUsed;
        };
        let outcome = apply(ekf, &position, c.gate);
        if let Some(v) = velocity {
            let _ = apply(ekf, &v, c.gate);
        }
        if outcome.is_accepted() {
            self.last_accepted_us[AidingSource::Gnss as usize] = Some(m.t_us);
        }
        match outcome {
            UpdateOutcome::Accepted { d2 } => GnssOutcome::Applied { d2 },
            _ => GnssOutcome::Outlier,
        }
    }
}

impl AidedNavigator {
    /// Re-sets the position (and the velocity, when reported) from the fix `m` after an outage
    /// or a re-admission:
    /// the antenna's position less the lever arm, its correlations dropped, its variance the
    /// fix's. The fix's measurement instant is taken as now (the outage was much longer than the
    /// receiver's latency; the latency's motion is within the variance given here).
    fn reset_from_fix(&mut self, m: &GnssMeasurement) -> GnssOutcome {
        let c = self.config.gnss;
        self.gnss.displacement.reset();
        let Some(ekf) = self.ekf_mut() else {
            return GnssOutcome::NotUsed;
        };
        let past = crate::state_history::PastState::now(ekf, Vector3::zeros());
        let arm = Vector3::from(c.lever_arm_m);
        let fix = antenna_position(&past, m.position, &arm, 1.0, 1.0);
        let (sh, sv) = (
            floor(m.sigma_h_m, c.sigma_horizontal_floor_m),
            floor(m.sigma_v_m, c.sigma_vertical_floor_m),
        );
        // Move by the innovation (fix − predicted antenna), then forget the old uncertainty.
        let d = fix.innovation;
        let s = ekf.state_mut();
        [s.lat, s.lon, s.alt] =
            rins_earth::LocalOrigin::new(s.lat, s.lon, s.alt).geodetic(d.into());
        for (k, sigma) in [sh, sh, sv].into_iter().enumerate() {
            ekf.reset_component(POS + k, sigma * sigma);
        }
        if let Some(v) = m.velocity_ned.filter(|_| c.use_velocity) {
            let sigma = floor(m.sigma_vel_mps, c.sigma_velocity_floor_mps);
            ekf.state_mut().velocity_ned = Vector3::from(v);
            for k in 0..3 {
                ekf.reset_component(crate::ekf::VEL + k, sigma * sigma);
            }
        }
        self.gnss.history.clear();
        self.last_accepted_us[AidingSource::Gnss as usize] = Some(m.t_us);
        self.integrity.set_position_unknown(false);
        GnssOutcome::Readmitted
    }
}

fn apply(ekf: &mut ErrorStateEkf, m: &Linearised, gate: f64) -> UpdateOutcome {
    ekf.update(AidingSource::Gnss, &m.h, &m.innovation, &m.r, gate)
}

/// The reported σ, raised to `min` (a σ that is not a number is `min`).
fn floor(sigma: f64, min: f64) -> f64 {
    if sigma.is_finite() {
        sigma.max(min)
    } else {
        min
    }
}
