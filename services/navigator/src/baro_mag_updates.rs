//! Barometric height and magnetometer heading updates of the [`AidedNavigator`]: the aiding
//! readings that arrive on their own topics, applied to the inertial core's filter.
//!
//! Both arrive on their own topics, older than (or as old as) the IMU sample last propagated; the
//! filter applies them to its current state. A baro reading further from the navigation time than
//! `max_lag_s` is dropped rather than applied to the wrong epoch.

use nalgebra::Vector3;

use crate::attitude::{rotation_vector_to_quaternion, wrap_pi};
use crate::ekf::{ATT, AidingSource, POS, UpdateOutcome, VEL};
use crate::inertial_core::AidedNavigator;
use crate::mag_heading::{FieldReference, adaptive_sigma, measured_heading};

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
    /// Persistently rejected while the reading itself is sound: the filter's state was re-set
    /// from it (altitude from the baro, heading from the magnetometer), see [`crate::integrity`].
    Reset,
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
            ekf.state_mut().alt = height_m;
            ekf.reset_component(POS + 2, c.floored_variance(variance_m2));
            self.last_accepted_us[AidingSource::Baro as usize] = Some(t_us);
            return AidingOutcome::Readmitted;
        }
        let lag_s = now_us.map_or(f64::INFINITY, |n| n.abs_diff(t_us) as f64 * 1e-6);
        if lag_s > c.max_lag_s {
            return AidingOutcome::Skipped;
        }
        let sigma = c.floored_variance(variance_m2).sqrt();
        let outcome = ekf.height(height_m, sigma, c.gate);
        if outcome.is_accepted() {
            self.last_accepted_us[AidingSource::Baro as usize] = Some(t_us);
        }
        self.integrity
            .on_update(AidingSource::Baro, t_us, outcome, 1);
        if self.integrity.wants_reset(AidingSource::Baro, t_us) {
            self.reset_altitude(t_us, height_m, sigma);
            return AidingOutcome::Reset;
        }
        AidingOutcome::Update(outcome)
    }

    /// Every baro height has been gated out for the persistence time while the filter claims to
    /// know its altitude: the filter is wrong (it integrated something that was not motion), not
    /// the barometer. The altitude is re-set from the reading and its correlations dropped; the
    /// vertical velocity keeps its value but its variance grows to cover it, so that the next
    /// readings correct it rather than face the gate again.
    fn reset_altitude(&mut self, t_us: u64, height_m: f64, sigma_m: f64) {
        let Some(ekf) = self.ekf_mut() else {
            return;
        };
        ekf.state_mut().alt = height_m;
        ekf.reset_component(POS + 2, sigma_m * sigma_m);
        let vd = ekf.state().velocity_ned[2];
        ekf.reset_component(VEL + 2, vd * vd + 1.0);
        self.last_accepted_us[AidingSource::Baro as usize] = Some(t_us);
        self.integrity.on_reset(AidingSource::Baro, t_us);
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
        self.integrity.on_update(source, t_us, outcome, 1);
        // Only an undisturbed field (every adaptive check passed) may re-set the heading.
        let undisturbed = sigma <= c.sigma_deg.to_radians();
        if undisturbed && self.integrity.wants_reset(source, t_us) {
            self.reset_heading(source, t_us, psi, sigma);
            return AidingOutcome::Reset;
        }
        if returning && outcome.is_accepted() {
            AidingOutcome::Readmitted
        } else {
            AidingOutcome::Update(outcome)
        }
    }

    /// Every heading update of `source` gated out for the persistence time, from a field that
    /// passes every disturbance check: the filter's heading is wrong (its gyros were out, or
    /// integrated something that was not motion). The attitude is turned about the vertical onto
    /// the measured heading and the heading error's correlations dropped.
    fn reset_heading(&mut self, source: AidingSource, t_us: u64, psi: f64, sigma: f64) {
        let Some(ekf) = self.ekf_mut() else {
            return;
        };
        let attitude = ekf.state().attitude;
        let c = attitude.to_rotation_matrix();
        let current = c[(1, 0)].atan2(c[(0, 0)]);
        let turn = rotation_vector_to_quaternion(&Vector3::new(0.0, 0.0, wrap_pi(psi - current)));
        let mut q = turn * attitude;
        q.renormalize();
        ekf.state_mut().attitude = q;
        ekf.reset_component(ATT + 2, sigma * sigma);
        self.last_accepted_us[source as usize] = Some(t_us);
        self.integrity.on_reset(source, t_us);
    }
}
