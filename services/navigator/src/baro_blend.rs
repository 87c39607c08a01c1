//! Second-order complementary blend of barometric height into the inertial vertical channel.
//!
//! With `e = h_baro − h_ins`, the loop adds `ḣ += k_h e` and `v̇_up += k_v e`. The error dynamics are
//! `ë + k_h ė + k_v e = (baro and accelerometer disturbances)`; the gains `k_h = 2/τ`, `k_v = 1/τ²` put a
//! double pole at `−1/τ` (critically damped). A baro step of size Δ starts with `e = Δ`, `ė = −k_h Δ` and
//! leaves the residual `Δ (1 − t/τ) e^{−t/τ}`: zero at τ, an overshoot of at most `Δ e^{−2}` (13.5 %) at
//! 2τ, 2.7 % at 5τ, zero in steady state. A constant vertical accelerometer
//! error `b` (positive up) leaves a steady height error `b τ²` and vertical-speed error `2 b τ`; removing it
//! needs the bias state of the error-state filter.
//!
//! The loop is applied as a discrete correction at each baro reading, scaled by the device time since the
//! previous reading. That interval is capped at τ/4 so that a reading after a long gap cannot overshoot
//! (`k_h Δt ≤ ½`). The inertial height is extrapolated to the reading's device time with the vertical
//! velocity before the comparison, so a reading that lags the IMU by a few milliseconds is not biased in a
//! climb.

use crate::mechanisation::NominalState;

/// Settings of the blend.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaroBlendConfig {
    /// Loop time constant τ, s.
    pub time_constant_s: f64,
    /// Largest accepted |reading time − state time|, s; older or newer readings are ignored.
    pub max_lag_s: f64,
}

impl Default for BaroBlendConfig {
    fn default() -> Self {
        Self {
            time_constant_s: 5.0,
            max_lag_s: 0.5,
        }
    }
}

/// What happened to a reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum BaroOutcome {
    /// The correction was applied; `innovation_m` is `h_baro − h_ins` at the reading time.
    Applied { innovation_m: f64 },
    /// The first reading only starts the clock of the loop.
    Started,
    /// The reading was flagged invalid or was not finite.
    Invalid,
    /// The reading is further than `max_lag_s` from the state time.
    Stale,
    /// The reading is not newer than the previous one.
    OutOfOrder,
}

/// The blend's gains and the device time of the last reading used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaroBlend {
    height_gain: f64,
    velocity_gain: f64,
    max_interval_s: f64,
    max_lag_us: i128,
    last_reading_us: Option<u64>,
}

impl BaroBlend {
    /// Gains from the time constant. A non-finite or non-positive τ disables the loop (zero gains);
    /// validate the configuration before.
    pub fn new(config: BaroBlendConfig) -> Self {
        let tau = config.time_constant_s;
        let (height_gain, velocity_gain) = if tau.is_finite() && tau > 0.0 {
            (2.0 / tau, 1.0 / (tau * tau))
        } else {
            (0.0, 0.0)
        };
        let max_lag_us = if config.max_lag_s.is_finite() && config.max_lag_s >= 0.0 {
            (config.max_lag_s * 1e6).round() as i128
        } else {
            0
        };
        Self {
            height_gain,
            velocity_gain,
            max_interval_s: 0.25 * tau.max(0.0),
            max_lag_us,
            last_reading_us: None,
        }
    }

    /// `k_h` (1/s) and `k_v` (1/s²).
    pub fn gains(&self) -> (f64, f64) {
        (self.height_gain, self.velocity_gain)
    }

    /// Device time of the last reading used, µs.
    pub fn last_reading_us(&self) -> Option<u64> {
        self.last_reading_us
    }

    /// Forgets the previous reading; the next valid one restarts the loop clock.
    pub fn restart(&mut self) {
        self.last_reading_us = None;
    }

    /// Blends one reading of height (m, positive up) taken at `reading_time_us` into `state`, whose
    /// epoch is `state_time_us` (same device clock). Allocation-free.
    pub fn apply(
        &mut self,
        state: &mut NominalState,
        state_time_us: u64,
        reading_time_us: u64,
        height_m: f64,
        valid: bool,
    ) -> BaroOutcome {
        if !valid || !height_m.is_finite() {
            return BaroOutcome::Invalid;
        }
        let lead_us = i128::from(reading_time_us) - i128::from(state_time_us);
        if lead_us.abs() > self.max_lag_us {
            return BaroOutcome::Stale;
        }
        let interval_s = match self.last_reading_us {
            None => {
                self.last_reading_us = Some(reading_time_us);
                return BaroOutcome::Started;
            }
            Some(last) if reading_time_us <= last => return BaroOutcome::OutOfOrder,
            Some(last) => ((reading_time_us - last) as f64 * 1e-6).min(self.max_interval_s),
        };
        self.last_reading_us = Some(reading_time_us);

        let vertical_speed_up = -state.velocity_ned.z;
        let ins_height = state.alt + vertical_speed_up * lead_us as f64 * 1e-6;
        let innovation = height_m - ins_height;
        state.alt += self.height_gain * innovation * interval_s;
        state.velocity_ned.z -= self.velocity_gain * innovation * interval_s;
        BaroOutcome::Applied {
            innovation_m: innovation,
        }
    }
}
