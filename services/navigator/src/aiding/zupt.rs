//! The zero-velocity update as an aiding source: a pseudo-measurement of zero velocity, applied
//! whenever the stance detector fires (`[navigator.stance]`).

use ipc_types::integrity_reason as why;
use rins_runtime::config_error::ConfigError;
use serde::{Deserialize, Serialize};

use crate::aiding::context::AidingContext;
use crate::aiding::source::{AidingSensor, Bucket};
use crate::checks::{Table, positive};
use crate::ekf::{AidingSource, UpdateOutcome};

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

    fn buckets(&self) -> &'static [Bucket] {
        &[Bucket {
            source: AidingSource::Zupt,
            inconsistent: why::ZUPT_INCONSISTENT,
        }]
    }

    fn enabled(&self) -> bool {
        self.enabled
    }

    /// A pseudo-measurement made from the IMU samples: it has no stream of its own to go quiet.
    fn watched_for_staleness(&self) -> bool {
        false
    }

    fn first_out_of_range(&self) -> Result<(), (&'static str, f64)> {
        positive("zupt.sigma_mps", self.sigma_mps)?;
        positive("zupt.gate", self.gate)
    }

    /// Its keys are named as `zupt.<key>` of `[navigator]`.
    fn section(&self) -> (&'static str, &'static str) {
        ("navigator", "must be finite and > 0")
    }

    /// As the default, with the unit of `sigma_mps` in its error.
    fn validate(&self) -> Result<(), ConfigError> {
        let positive = |x: f64| x > 0.0;
        Table("navigator").check(
            "zupt.sigma_mps",
            self.sigma_mps,
            positive,
            "must be finite and > 0 m/s",
        )?;
        Table("navigator").check("zupt.gate", self.gate, positive, "must be finite and > 0")
    }
}

/// The zero-velocity aiding: its settings (it keeps nothing between updates).
#[derive(Debug, Clone, Copy)]
pub(crate) struct ZuptAiding {
    config: ZuptConfig,
}

impl ZuptAiding {
    pub(crate) fn new(config: ZuptConfig) -> Self {
        Self { config }
    }

    /// The IMU sample at `t_us`, propagated, was taken in stance: the update, booked, when the
    /// profile applies it.
    pub(crate) fn on_stance(
        &self,
        ctx: &mut AidingContext<'_>,
        t_us: u64,
    ) -> Option<UpdateOutcome> {
        let z = self.config;
        if !z.enabled {
            return None;
        }
        let result = ctx.filter_mut()?.zupt(z.sigma_mps, z.gate);
        ctx.book_update(AidingSource::Zupt, t_us, result, 3);
        Some(result)
    }
}
