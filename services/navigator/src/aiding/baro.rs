//! Barometric height updates of the [`AidedNavigator`]: readings that arrive on their own topic,
//! older than (or as old as) the IMU sample last propagated, applied to the filter's current
//! state. A reading further from the navigation time than `max_lag_s` is dropped rather than
//! applied to the wrong epoch.

use crate::aiding::outcome::AidingOutcome;
use crate::aiding::source::AidingSensor;
use crate::baro_height::BaroAidingConfig;
use crate::ekf::{AidingSource, POS, VEL};
use crate::inertial_core::AidedNavigator;

impl AidingSensor for BaroAidingConfig {
    fn source(&self) -> AidingSource {
        AidingSource::Baro
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    fn watched_for_staleness(&self) -> bool {
        true
    }
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
        self.book_update(AidingSource::Baro, t_us, outcome, 1);
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
        self.book_reset(AidingSource::Baro, t_us);
    }
}
