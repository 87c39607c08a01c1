//! Foot-mounted (pedestrian profile) evaluation on recorded walks, with the navigator library
//! and no IPC: `rins eval pyshoe DIR` (2-D error against Vicon per trial, on our metric and on the
//! peer's) and `rins eval xio FILE…` (end-point error of closed-loop walks).
//!
//! Two estimators: rins (the pedestrian profile's navigator) and the peer's published method
//! ([`reference`]). Each has one setting chosen from data, its stance threshold, and that choice
//! is made leave-one-trial-out: every trial is scored with the threshold that did best on the
//! other trials, and that held-out figure is the one reported.

pub mod detectors;
pub mod live;
pub mod metrics;
pub mod plot;
pub mod pyshoe_eval;
pub mod reference;
pub mod report;
pub mod run;
pub mod strides;
pub mod xio_eval;

use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::stance::StanceTest;
use serde::Serialize;

use crate::datasets::foot::FootTrial;

pub use pyshoe_eval::{
    PyshoeOptions, PyshoeReport, PyshoeTrial, evaluate_pyshoe, evaluate_pyshoe_with_runs,
};
pub use xio_eval::{XioReport, XioWalk, evaluate_xio};

/// Which estimator the per-trial figures, the means and the plots are of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FootMethod {
    /// The product: the pedestrian profile's navigator.
    #[default]
    Rins,
    /// The peer's published method, SHOE + zero-velocity EKF ([`reference`]).
    Reference,
}

/// A trial that could not be evaluated, and why; the others go on.
#[derive(Debug, Clone, Serialize)]
pub struct Skipped {
    /// The file.
    pub file: String,
    /// What was wrong with it.
    pub reason: String,
}

/// Multiples of the profile's SHOE threshold tried for rins, smallest first: 2.625e4 … 1.05e5
/// with the pedestrian profile (7.35e4), the range the threshold has been chosen from since the
/// profile's first walks.
pub const RINS_THRESHOLD_FACTORS: [f64; 5] = [1.0 / 2.8, 1.4 / 2.8, 2.0 / 2.8, 1.0, 4.0 / 2.8];
/// Raise factors tried for rins (`[navigator.stance] raise_factor`; 1 = never raised), each
/// after the profile's `raise_after_samples` (1 s at 200 Hz when the profile leaves it off).
pub const RINS_RAISE_FACTORS: [f64; 4] = [1.0, 2.0, 4.0, 8.0];
/// Gait exponents tried for rins (`[navigator.stance] gait_exponent`; 0 = a fixed threshold).
pub const RINS_GAIT_EXPONENTS: [f64; 3] = [0.0, 0.25, 0.5];
/// Gyro lags tried for rins (`[navigator] gyro_lag_s`, s; 0 = rate and force taken as sampled).
pub const RINS_GYRO_LAGS_S: [f64; 3] = [0.0, 0.005, 0.01];
/// `raise_after_samples` tried when the profile has none.
pub const DEFAULT_RAISE_AFTER_SAMPLES: usize = 200;

/// Thresholds tried for the reference method: 10^(6 + i/4), i = 0..=12 (1e6 … 1e9), the range
/// in which the peer's per-trial optima of its SHOE detector lie.
pub fn reference_thresholds() -> Vec<f64> {
    (0..=12)
        .map(|i| 10f64.powf(6.0 + f64::from(i) / 4.0))
        .collect()
}

/// The rins candidates: the profile with its SHOE threshold scaled by each of
/// [`RINS_THRESHOLD_FACTORS`], raised by each of [`RINS_RAISE_FACTORS`], adapted to the gait
/// with each of [`RINS_GAIT_EXPONENTS`] and its rate paired with the force of each of
/// [`RINS_GYRO_LAGS_S`] earlier; the profile alone when its detector is not SHOE.
pub fn rins_candidates(config: &AidedConfig) -> Vec<AidedConfig> {
    let StanceTest::Shoe { threshold, .. } = config.stance.detector else {
        return vec![*config];
    };
    let raise_after = match config.stance.raise_after_samples {
        0 => DEFAULT_RAISE_AFTER_SAMPLES,
        n => n,
    };
    let mut out = Vec::new();
    for gyro_lag_s in RINS_GYRO_LAGS_S {
        for gait_exponent in RINS_GAIT_EXPONENTS {
            for raise in RINS_RAISE_FACTORS {
                for f in RINS_THRESHOLD_FACTORS {
                    let mut c = *config;
                    if let StanceTest::Shoe { threshold: t, .. } = &mut c.stance.detector {
                        *t = threshold * f;
                    }
                    c.stance.raise_factor = raise;
                    c.stance.raise_after_samples = if raise > 1.0 { raise_after } else { 0 };
                    c.stance.gait_exponent = gait_exponent;
                    c.gyro_lag_s = gyro_lag_s;
                    out.push(c);
                }
            }
        }
    }
    out
}

/// The SHOE or ARED threshold of a configuration (NaN for the other detectors).
pub fn stance_threshold(config: &AidedConfig) -> f64 {
    match config.stance.detector {
        StanceTest::Shoe { threshold, .. } | StanceTest::Ared { threshold, .. } => threshold,
        _ => f64::NAN,
    }
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

/// The accelerometer and gyro columns of a trial.
fn columns(trial: &FootTrial) -> (Vec<[f64; 3]>, Vec<[f64; 3]>) {
    (
        trial.samples.iter().map(|s| s.accel_mps2).collect(),
        trial.samples.iter().map(|s| s.gyro_rps).collect(),
    )
}
