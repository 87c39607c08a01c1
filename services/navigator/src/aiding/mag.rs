//! The magnetometer as an aiding source: samples that arrive on their own topic, calibrated, then
//! used for the alignment heading or applied to the filter's current state (as a stance heading
//! update, HUPT, when `stance_only`). The measurement model and its adaptive noise are in
//! [`crate::aiding::mag_heading`].

use ipc_types::{RawMag, integrity_reason as why};
use nalgebra::Vector3;

use crate::aiding::context::AidingContext;
use crate::aiding::mag_heading::{
    FieldReference, MagAidingConfig, adaptive_sigma, measured_heading,
};
use crate::aiding::outcome::AidingOutcome;
use crate::aiding::source::{AidingSensor, Bucket};
use crate::alignment::Alignment;
use crate::attitude::{rotation_vector_to_quaternion, wrap_pi};
use crate::ekf::{ATT, AidingSource};
use crate::mag_calibration::MagCalibration;

/// One raw magnetometer sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MagReading {
    /// Device time, µs.
    pub t_us: u64,
    /// Raw field, µT, body FRD.
    pub field_ut: [f64; 3],
}

impl MagReading {
    /// A raw magnetometer sample as the sensor block publishes it.
    pub fn from_raw(mag: &RawMag) -> Self {
        Self {
            t_us: mag.header.origin_device_time_us,
            field_ut: mag.field_ut.map(f64::from),
        }
    }
}

impl AidingSensor for MagAidingConfig {
    /// Heading updates in stance only are booked as HUPT, the others as magnetometer updates.
    fn source(&self) -> AidingSource {
        if self.stance_only {
            AidingSource::Hupt
        } else {
            AidingSource::Mag
        }
    }

    /// A stance heading that disagrees is reported as the stance updates' inconsistency.
    fn buckets(&self) -> &'static [Bucket] {
        &[
            Bucket {
                source: AidingSource::Mag,
                inconsistent: why::MAG_INCONSISTENT,
            },
            Bucket {
                source: AidingSource::Hupt,
                inconsistent: why::ZUPT_INCONSISTENT,
            },
        ]
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    /// In stance only, samples are used only while the foot is still: a gap between uses is
    /// the gait, not an outage.
    fn watched_for_staleness(&self) -> bool {
        !self.stance_only
    }

    fn first_out_of_range(&self) -> Result<(), (&'static str, f64)> {
        self.check()
    }

    fn section(&self) -> (&'static str, &'static str) {
        (
            "navigator.mag",
            "out of range (inflation >= 1, max_rate_hz >= 0, others finite and > 0)",
        )
    }
}

/// The magnetometer aiding: its settings, the field reference and the rate limit.
#[derive(Debug, Clone)]
pub(crate) struct MagAiding {
    config: MagAidingConfig,
    /// Applied to every sample before use.
    calibration: MagCalibration,
    /// Declination, rad, positive east.
    declination_rad: f64,
    /// Device time of the last heading update attempted, µs (rate limit).
    last_update_us: Option<u64>,
    /// Magnitude and dip of the field in the alignment window.
    field_reference: Option<FieldReference>,
    /// The reference comes from the first sample after a takeover (there was no alignment
    /// window of our own to take it from).
    reference_from_next: bool,
}

impl MagAiding {
    pub(crate) fn new(
        config: MagAidingConfig,
        calibration: MagCalibration,
        declination_rad: f64,
    ) -> Self {
        Self {
            config,
            calibration,
            declination_rad,
            last_update_us: None,
            field_reference: None,
            reference_from_next: false,
        }
    }

    /// Navigation starts from the alignment `a`: the field reference is its mean field.
    pub(crate) fn on_aligned(&mut self, a: &Alignment) {
        self.field_reference = a
            .mean_field_ut
            .and_then(|m| FieldReference::from_field(&m, &a.attitude));
    }

    /// Navigation goes on from a solution taken over: the reference is taken from the next
    /// sample at the taken-over attitude.
    pub(crate) fn on_take_over(&mut self) {
        self.field_reference = None;
        self.reference_from_next = true;
    }

    /// One magnetometer sample (raw µT, body FRD) at device time `t_us`: calibrated, then used
    /// for the alignment heading, or as a heading update (only in stance, counted as HUPT, when
    /// `stance_only`).
    pub(crate) fn on_reading(
        &mut self,
        ctx: &mut AidingContext<'_>,
        r: MagReading,
    ) -> AidingOutcome {
        let MagReading {
            t_us,
            field_ut: raw_ut,
        } = r;
        if raw_ut.iter().any(|x| !x.is_finite()) {
            return AidingOutcome::Skipped;
        }
        let field = self.calibration.apply(raw_ut);
        if let Some(aligner) = ctx.aligner_mut() {
            aligner.push_mag(t_us, field);
            return AidingOutcome::Stored;
        }
        let c = self.config;
        if !c.enabled || (c.stance_only && !ctx.in_stance()) {
            return AidingOutcome::Skipped;
        }
        // Back after an outage: the heading has coasted on the gyros; the first reading is
        // applied whatever its innovation, the following ones are gated again.
        let returning = ctx.is_stale(AidingSource::Mag);
        ctx.note_reading(AidingSource::Mag, t_us);
        if c.max_rate_hz > 0.0
            && let Some(last) = self.last_update_us
            && (t_us.saturating_sub(last) as f64) < 1e6 / c.max_rate_hz
        {
            return AidingOutcome::Skipped;
        }
        if self.field_reference.is_none()
            && self.reference_from_next
            && let Some(ekf) = ctx.filter()
        {
            let attitude = ekf.state().attitude;
            self.field_reference = FieldReference::from_field(&Vector3::from(field), &attitude);
            self.reference_from_next = false;
        }
        let Some(reference) = self.field_reference else {
            return AidingOutcome::Skipped;
        };
        let (declination, force) = (self.declination_rad, ctx.force());
        let source = c.source();
        let Some(ekf) = ctx.filter_mut() else {
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
        self.last_update_us = Some(t_us);
        ctx.book_update(source, t_us, outcome, 1);
        // Only an undisturbed field (every adaptive check passed) may re-set the heading.
        let undisturbed = sigma <= c.sigma_deg.to_radians();
        if undisturbed && ctx.wants_reset(source, t_us) {
            reset_heading(ctx, source, t_us, psi, sigma);
            return AidingOutcome::Reset;
        }
        if returning && outcome.is_accepted() {
            AidingOutcome::Readmitted
        } else {
            AidingOutcome::Update(outcome)
        }
    }
}

/// Every heading update of `source` gated out for the persistence time, from a field that
/// passes every disturbance check: the filter's heading is wrong (its gyros were out, or
/// integrated something that was not motion). The attitude is turned about the vertical onto
/// the measured heading and the heading error's correlations dropped.
fn reset_heading(
    ctx: &mut AidingContext<'_>,
    source: AidingSource,
    t_us: u64,
    psi: f64,
    sigma: f64,
) {
    let Some(ekf) = ctx.filter_mut() else {
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
    ctx.book_reset(source, t_us);
}
