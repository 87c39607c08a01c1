//! The zero-velocity update as an aiding source: its settings; it is applied in the inertial core
//! whenever the stance detector fires (see [`crate::inertial_core`]).

use serde::{Deserialize, Serialize};

use crate::aiding::source::AidingSensor;
use crate::ekf::AidingSource;

/// Settings of the zero-velocity aiding (`[navigator.zupt]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZuptConfig {
    /// Apply a zero-velocity update whenever the stance detector fires (`[navigator.stance]`).
    pub enabled: bool,
    /// Velocity σ of the zero-velocity pseudo-measurement, m/s per axis.
    pub sigma_mps: f64,
    /// Innovation gate: largest accepted Mahalanobis distance of the velocity innovation.
    pub gate: f64,
}

impl Default for ZuptConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            sigma_mps: 0.01,
            gate: 1e3,
        }
    }
}

impl AidingSensor for ZuptConfig {
    fn source(&self) -> AidingSource {
        AidingSource::Zupt
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    /// A pseudo-measurement made from the IMU samples: it has no stream of its own to go quiet.
    fn watched_for_staleness(&self) -> bool {
        false
    }
}
