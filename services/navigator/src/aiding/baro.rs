//! The barometric altimeter as an aiding source (`[navigator.baro]`): height readings that arrive
//! on their own topic, older than (or as old as) the IMU sample last propagated, applied to the
//! filter's current state. A reading further from the navigation time than `max_lag_s` is dropped
//! rather than applied to the wrong epoch. The first valid reading is the altitude navigation
//! starts from.

use ipc_types::{Altitude, integrity_reason as why};
use serde::{Deserialize, Serialize};

use crate::aiding::context::AidingContext;
use crate::aiding::outcome::AidingOutcome;
use crate::aiding::source::stream_aiding_sensor;
use crate::checks::positive;
use crate::ekf::{AidingSource, POS, VEL};

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

    /// The variance a height update uses, m²: the altimeter's `variance_m2` (0 when it is not a
    /// number), raised to at least `sigma_floor_m²`.
    pub fn floored_variance(&self, variance_m2: f64) -> f64 {
        let variance = if variance_m2.is_finite() {
            variance_m2
        } else {
            0.0
        };
        variance.max(self.sigma_floor_m * self.sigma_floor_m)
    }
}

stream_aiding_sensor!(
    BaroAidingConfig => Baro,
    inconsistent: why::BARO_INCONSISTENT,
    section: "navigator.baro",
    range: "must be finite and > 0",
);

/// One barometric height as the altimeter publishes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaroReading {
    /// Device time, µs.
    pub t_us: u64,
    /// Height above mean sea level, m.
    pub height_m: f64,
    /// Its variance, m².
    pub variance_m2: f64,
    /// The altimeter's validity flag.
    pub valid: bool,
}

impl BaroReading {
    /// The altimeter's height.
    pub fn from_altitude(alt: &Altitude) -> Self {
        Self {
            t_us: alt.header.origin_device_time_us,
            height_m: alt.height_m,
            variance_m2: alt.height_var,
            valid: alt.valid != 0,
        }
    }
}

/// The barometric aiding: its settings and the first valid height.
#[derive(Debug, Clone)]
pub(crate) struct BaroAiding {
    config: BaroAidingConfig,
    /// First valid baro height, m: the altitude navigation starts from.
    initial_height_m: Option<f64>,
}

impl BaroAiding {
    pub(crate) fn new(config: BaroAidingConfig) -> Self {
        Self {
            config,
            initial_height_m: None,
        }
    }

    /// The altitude navigation starts from, when a valid reading came.
    pub(crate) fn initial_height_m(&self) -> Option<f64> {
        self.initial_height_m
    }

    /// Navigation goes on from a solution taken over at altitude `alt_m`: it is baro-aided
    /// already, so no reading re-sets it.
    pub(crate) fn on_take_over(&mut self, alt_m: f64) {
        self.initial_height_m = Some(alt_m);
    }

    /// One barometric height (m above mean sea level) with its variance (m²) at device time
    /// `t_us`. Before alignment the first valid reading becomes the starting altitude; the first
    /// reading after an alignment without one sets the altitude directly.
    pub(crate) fn on_reading(
        &mut self,
        ctx: &mut AidingContext<'_>,
        r: BaroReading,
    ) -> AidingOutcome {
        let BaroReading {
            t_us,
            height_m,
            variance_m2,
            valid,
        } = r;
        let c = self.config;
        if !valid || !height_m.is_finite() {
            return AidingOutcome::Skipped;
        }
        let first = self.initial_height_m.is_none();
        if first {
            self.initial_height_m = Some(height_m);
        }
        // Back after an outage: the altitude has coasted on the accelerometers and the weather
        // may have moved the baro; the reading re-sets the altitude rather than face the gate.
        let returning = c.enabled && ctx.is_stale(AidingSource::Baro);
        ctx.note_reading(AidingSource::Baro, t_us);
        let now_us = ctx.time_us();
        let Some(ekf) = ctx.filter_mut() else {
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
            ctx.note_accepted(AidingSource::Baro, t_us);
            return AidingOutcome::Readmitted;
        }
        let lag_s = now_us.map_or(f64::INFINITY, |n| n.abs_diff(t_us) as f64 * 1e-6);
        if lag_s > c.max_lag_s {
            return AidingOutcome::Skipped;
        }
        let sigma = c.floored_variance(variance_m2).sqrt();
        let outcome = ekf.height(height_m, sigma, c.gate);
        ctx.book_update(AidingSource::Baro, t_us, outcome, 1);
        if ctx.wants_reset(AidingSource::Baro, t_us) {
            reset_altitude(ctx, t_us, height_m, sigma);
            return AidingOutcome::Reset;
        }
        AidingOutcome::Update(outcome)
    }
}

/// Every baro height has been gated out for the persistence time while the filter claims to
/// know its altitude: the filter is wrong (it integrated something that was not motion), not
/// the barometer. The altitude is re-set from the reading and its correlations dropped; the
/// vertical velocity keeps its value but its variance grows to cover it, so that the next
/// readings correct it rather than face the gate again.
fn reset_altitude(ctx: &mut AidingContext<'_>, t_us: u64, height_m: f64, sigma_m: f64) {
    let Some(ekf) = ctx.filter_mut() else {
        return;
    };
    ekf.state_mut().alt = height_m;
    ekf.reset_component(POS + 2, sigma_m * sigma_m);
    let vd = ekf.state().velocity_ned[2];
    ekf.reset_component(VEL + 2, vd * vd + 1.0);
    ctx.book_reset(AidingSource::Baro, t_us);
}
