//! The stance detectors side by side on the same trials, each with its settings chosen
//! leave-one-trial-out: SHOE with one fixed threshold, SHOE with the threshold following the
//! gait, and ARED (the rate energy alone; Skog, Händel, Nilsson and Rantakokko, "Zero-velocity
//! detection — an algorithm evaluation").

use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::stance::StanceTest;
use serde::Serialize;

use super::metrics::round_mm;
use super::{RINS_GYRO_LAGS_S, RINS_THRESHOLD_FACTORS, mean, rins_candidates, stance_threshold};
use crate::leave_one_out::{choose_on_all, choose_without_each};

/// A detector family the evaluation compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Detector {
    /// SHOE, one fixed threshold.
    Shoe,
    /// SHOE, its threshold following the gait (`gait_exponent` chosen with it).
    ShoeGait,
    /// ARED, one fixed threshold.
    Ared,
}

impl Detector {
    /// The family's name, as the JSON spells it.
    pub fn name(self) -> &'static str {
        match self {
            Detector::Shoe => "shoe",
            Detector::ShoeGait => "shoe_gait",
            Detector::Ared => "ared",
        }
    }
}

/// One family's cross-validated figures.
#[derive(Debug, Clone, Serialize)]
pub struct DetectorFigure {
    /// The family.
    pub detector: Detector,
    /// Mean ARMSE (the peer's metric), each trial with the family's setting chosen on the others, m.
    pub mean_armse_m: f64,
    /// Trials on which that beat the peer's per-trial-tuned best (1 mm rounding).
    pub trials_better_than_peer: usize,
    /// The threshold chosen on every trial.
    pub threshold_all: f64,
    /// The gait exponent chosen on every trial.
    pub gait_exponent_all: f64,
    /// The raise factor chosen on every trial.
    pub raise_factor_all: f64,
}

/// Multiples of 2.625e4 (the smallest SHOE threshold tried with the pedestrian profile) tried for
/// ARED: its statistic is SHOE's rate term alone, so it sits below SHOE's for the same window;
/// the range reaches four octaves lower.
pub const ARED_THRESHOLD_FACTORS: [f64; 7] = [0.0625, 0.125, 0.25, 0.5, 1.0, 2.0, 4.0];

/// Every candidate of the comparison with its family: the SHOE grid of [`rins_candidates`]
/// (fixed when its gait exponent is 0), then ARED with the profile's gyro σ, each of
/// [`ARED_THRESHOLD_FACTORS`] of the smallest SHOE threshold, the SHOE grid's raise factors and
/// each of [`RINS_GYRO_LAGS_S`]. Only the SHOE grid when the profile's detector is not SHOE.
pub fn comparison_candidates(config: &AidedConfig) -> Vec<(Detector, AidedConfig)> {
    let shoe = rins_candidates(config);
    let mut out: Vec<(Detector, AidedConfig)> = shoe
        .iter()
        .map(|c| {
            let family = if c.stance.gait_exponent > 0.0 {
                Detector::ShoeGait
            } else {
                Detector::Shoe
            };
            (family, *c)
        })
        .collect();
    let StanceTest::Shoe {
        gyro_sigma_rps,
        threshold,
        ..
    } = config.stance.detector
    else {
        return out;
    };
    let threshold = threshold * RINS_THRESHOLD_FACTORS[0];
    let mut raises: Vec<(f64, usize)> = shoe
        .iter()
        .map(|c| (c.stance.raise_factor, c.stance.raise_after_samples))
        .collect();
    raises.sort_by(|a, b| a.0.total_cmp(&b.0));
    raises.dedup();
    for gyro_lag_s in RINS_GYRO_LAGS_S {
        for &(raise_factor, raise_after_samples) in &raises {
            for f in ARED_THRESHOLD_FACTORS {
                let mut ared = *config;
                ared.stance.detector = StanceTest::Ared {
                    gyro_sigma_rps,
                    threshold: threshold * f,
                };
                ared.stance.gait_exponent = 0.0;
                ared.stance.raise_factor = raise_factor;
                ared.stance.raise_after_samples = raise_after_samples;
                ared.gyro_lag_s = gyro_lag_s;
                out.push((Detector::Ared, ared));
            }
        }
    }
    out
}

/// The families a figure is chosen among: SHOE with the gait may also choose a fixed threshold.
fn member(detector: Detector, family: Detector) -> bool {
    family == detector || (detector == Detector::ShoeGait && family == Detector::Shoe)
}

/// `log_scores[trial][candidate]` of [`comparison_candidates`] (the log of each ARMSE, so the
/// choice minimises the geometric mean: one trial diverging under every setting does not decide
/// alone); `armse[trial][candidate]` the figures; `peer[trial]` the peer's best.
pub fn compare(
    candidates: &[(Detector, AidedConfig)],
    armse: &[Vec<f64>],
    log_scores: &[Vec<f64>],
    peer: &[Option<f64>],
) -> Vec<DetectorFigure> {
    [Detector::Shoe, Detector::ShoeGait, Detector::Ared]
        .into_iter()
        .filter_map(|detector| {
            let members: Vec<usize> = (0..candidates.len())
                .filter(|&k| member(detector, candidates[k].0))
                .collect();
            if members.is_empty() {
                return None;
            }
            let sub = |m: &[Vec<f64>]| -> Vec<Vec<f64>> {
                m.iter()
                    .map(|row| members.iter().map(|&k| row[k]).collect())
                    .collect()
            };
            let chosen = choose_without_each(&sub(log_scores));
            let held_out: Vec<f64> = chosen
                .iter()
                .enumerate()
                .map(|(trial, &c)| armse[trial][members[c]])
                .collect();
            let all = candidates[members[choose_on_all(&sub(log_scores))]].1;
            let threshold_all = stance_threshold(&all);
            Some(DetectorFigure {
                detector,
                mean_armse_m: mean(held_out.iter().copied()),
                trials_better_than_peer: held_out
                    .iter()
                    .zip(peer)
                    .filter(|(a, p)| p.is_some_and(|p| round_mm(**a) < p))
                    .count(),
                threshold_all,
                gait_exponent_all: all.stance.gait_exponent,
                raise_factor_all: all.stance.raise_factor,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_family_is_chosen_among_its_own_candidates_held_out() {
        let profile = rins_navigator::NavigatorConfig::default().aided_config();
        let candidates = comparison_candidates(&profile);
        let n = candidates.len();
        // Two trials; the fixed SHOE candidate 0 is best on both, the first ARED one next.
        let first_ared = candidates
            .iter()
            .position(|c| c.0 == Detector::Ared)
            .unwrap_or(n);
        let row = |t: f64| -> Vec<f64> {
            (0..n)
                .map(|k| match k {
                    0 => 0.01 * t,
                    k if k == first_ared => 0.02 * t,
                    _ => 0.5,
                })
                .collect()
        };
        let armse = vec![row(1.0), row(2.0)];
        let logs: Vec<Vec<f64>> = armse
            .iter()
            .map(|r| r.iter().map(|v| v.ln()).collect())
            .collect();
        let figures = compare(&candidates, &armse, &logs, &[Some(0.015), None]);
        let by = |d: Detector| {
            figures
                .iter()
                .find(|f| f.detector == d)
                .map(|f| f.mean_armse_m)
        };
        // SHOE fixed and SHOE with the gait (which may choose the fixed one) both find 0: 0.015.
        assert!((by(Detector::Shoe).unwrap_or(0.0) - 0.015).abs() < 1e-12);
        assert!((by(Detector::ShoeGait).unwrap_or(0.0) - 0.015).abs() < 1e-12);
        assert!((by(Detector::Ared).unwrap_or(0.0) - 0.03).abs() < 1e-12);
        // Only trial 0 has a peer figure: 0.010 beats 0.015, 0.020 does not.
        let better = |d: Detector| {
            figures
                .iter()
                .find(|f| f.detector == d)
                .map(|f| f.trials_better_than_peer)
        };
        assert_eq!(better(Detector::Shoe), Some(1));
        assert_eq!(better(Detector::Ared), Some(0));
    }
}
