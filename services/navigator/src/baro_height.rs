//! Settings of the barometric height aiding (`[navigator.baro]`) and the variance a height update
//! takes from them; the updates themselves are in [`crate::aiding`].

use serde::{Deserialize, Serialize};

use crate::checks::positive;

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
