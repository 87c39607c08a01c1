//! Magnetometer heading updates of the [`AidedNavigator`]: samples that arrive on their own topic,
//! calibrated, then used for the alignment heading or applied to the filter's current state
//! (as a stance heading update, HUPT, when `stance_only`).

use nalgebra::Vector3;

use crate::aiding::outcome::AidingOutcome;
use crate::aiding::source::AidingSensor;
use crate::attitude::{rotation_vector_to_quaternion, wrap_pi};
use crate::ekf::{ATT, AidingSource};
use crate::inertial_core::AidedNavigator;
use crate::mag_heading::{FieldReference, MagAidingConfig, adaptive_sigma, measured_heading};

impl AidingSensor for MagAidingConfig {
    /// Heading updates in stance only are booked as HUPT, the others as magnetometer updates.
    fn source(&self) -> AidingSource {
        if self.stance_only {
            AidingSource::Hupt
        } else {
            AidingSource::Mag
        }
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    /// In stance only, samples are used only while the foot is still: a gap between uses is
    /// the gait, not an outage.
    fn watched_for_staleness(&self) -> bool {
        !self.stance_only
    }
}

impl AidedNavigator {
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
        self.book_update(source, t_us, outcome, 1);
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
        self.book_reset(source, t_us);
    }
}
