//! The held-out rins run of each pyshoe walk, kept so that the running service (fusion and the
//! navigator lanes as separate processes) can repeat it and be scored the same way
//! (`rins eval pyshoe --live`).

use rins_earth::{meridian_radius, prime_vertical_radius};
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use super::metrics::{aligned_rmse_2d, peer_armse_2d};
use super::run::{FootRun, run_trial};
use crate::datasets::foot::{FootSample, FootTrial};

/// A walk's figures on both metrics.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WalkScore {
    /// The peer's metric, m.
    pub armse_m: f64,
    /// Our metric: 2-D RMSE from the alignment on, after a fit of the start and heading, m.
    pub rmse_2d_m: f64,
    /// The rotation the peer's metric applied, rad.
    pub rotation_rad: f64,
}

fn horizontal(points: &[[f64; 3]]) -> Vec<[f64; 2]> {
    points.iter().map(|p| [p[0], p[1]]).collect()
}

/// Scores per-sample positions (north, east, down from the origin; zero while aligning) that
/// start navigating at sample `aligned_at` against the truth.
///
/// The estimate's north, east are matched with the export's Vicon x, y: with the Vicon z up, that
/// pair is mirrored, so the export's horizontal axes do not form the right-handed frame their z
/// suggests; matched this way every trial fits within centimetres (the peer's own evaluation
/// pairs them the same way). Only a rotation is ever fitted, never a reflection.
pub fn score_positions(
    ned_m: &[[f64; 3]],
    aligned_at: Option<usize>,
    truth: &[[f64; 3]],
) -> WalkScore {
    let truth_xy = horizontal(truth);
    let estimate = horizontal(ned_m);
    let peer = peer_armse_2d(&estimate, &truth_xy);
    let start = aligned_at.unwrap_or(ned_m.len());
    let rmse_2d_m = if start < estimate.len().min(truth_xy.len()) {
        aligned_rmse_2d(&estimate[start..], &truth_xy[start..]).0
    } else {
        f64::NAN
    };
    WalkScore {
        armse_m: peer.armse_m,
        rmse_2d_m,
        rotation_rad: peer.rotation_rad,
    }
}

/// Positions on a walk's sample base.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PositionTrace {
    /// North, east, down from the origin per sample, m; zero before the first navigating sample.
    pub ned_m: Vec<[f64; 3]>,
    /// The first navigating sample.
    pub aligned_at: Option<usize>,
    /// Samples after `aligned_at` with no published position (the previous one held).
    pub missing: usize,
}

/// One walk's scored held-out rins run: what it was given and what it produced in process.
#[derive(Debug, Clone)]
pub struct ScoredWalk {
    /// The walk as loaded.
    pub trial: FootTrial,
    /// The Vicon positions, one per sample.
    pub truth: Vec<[f64; 3]>,
    /// The held-out navigator settings the walk was scored with.
    pub config: AidedConfig,
    /// The in-process run.
    pub run: FootRun,
}

impl ScoredWalk {
    /// Runs `trial` in process with `config`, as the evaluation scores it.
    pub fn new(trial: FootTrial, truth: Vec<[f64; 3]>, config: AidedConfig) -> Self {
        let run = run_trial(&trial, &config);
        Self {
            trial,
            truth,
            config,
            run,
        }
    }

    /// The navigator settings the run uses: those scored, with the barometer and magnetometer
    /// aiding off (the recordings carry neither).
    pub fn navigator_config(&self) -> AidedConfig {
        let mut c = self.config;
        c.baro.enabled = false;
        c.mag.enabled = false;
        c
    }

    /// The in-process run as a trace.
    pub fn trace(&self) -> PositionTrace {
        PositionTrace {
            ned_m: self.run.ned_m.clone(),
            aligned_at: self.run.aligned_at,
            missing: 0,
        }
    }

    /// The same run in process on other samples of the walk (e.g. as a converter quantised
    /// them and fusion corrected them), one per sample of the walk.
    pub fn rerun(
        &self,
        gyro_accel: impl IntoIterator<Item = ([f64; 3], [f64; 3])>,
    ) -> PositionTrace {
        let samples: Vec<FootSample> = self
            .trial
            .samples
            .iter()
            .zip(gyro_accel)
            .map(|(s, (gyro_rps, accel_mps2))| FootSample {
                t_s: s.t_s,
                gyro_rps,
                accel_mps2,
            })
            .collect();
        let trial = FootTrial {
            samples,
            ..self.trial.clone()
        };
        let run = run_trial(&trial, &self.config);
        PositionTrace {
            ned_m: run.ned_m,
            aligned_at: run.aligned_at,
            missing: 0,
        }
    }

    /// The positions a running navigator published, `(sample index, [lat, lon, alt])` of each
    /// navigating sample in order, as a trace on the walk's sample base, north, east, down from
    /// the configured origin as the in-process run measures them.
    pub fn trace_from(
        &self,
        published: impl IntoIterator<Item = (usize, [f64; 3])>,
    ) -> PositionTrace {
        let n = self.trial.samples.len();
        let [lat0, lon0, alt0] = self.config.origin;
        let (rn, re) = (
            meridian_radius(lat0) + alt0,
            prime_vertical_radius(lat0) + alt0,
        );
        let mut slots: Vec<Option<[f64; 3]>> = vec![None; n];
        for (j, [lat, lon, alt]) in published {
            if let Some(slot) = slots.get_mut(j) {
                *slot = Some([
                    (lat - lat0) * rn,
                    (lon - lon0) * re * lat0.cos(),
                    alt0 - alt,
                ]);
            }
        }
        let aligned_at = slots.iter().position(Option::is_some);
        let mut trace = PositionTrace {
            ned_m: Vec::with_capacity(n),
            aligned_at,
            missing: 0,
        };
        let mut last = [0.0; 3];
        for (j, slot) in slots.into_iter().enumerate() {
            match slot {
                Some(p) => last = p,
                None if aligned_at.is_some_and(|a| j > a) => trace.missing += 1,
                None => {}
            }
            trace.ned_m.push(last);
        }
        trace
    }

    /// `trace` scored exactly as the in-process run.
    pub fn score(&self, trace: &PositionTrace) -> WalkScore {
        score_positions(&trace.ned_m, trace.aligned_at, &self.truth)
    }

    /// The largest horizontal distance between `a` and `b` at the scored samples (every sample
    /// of the walk: the peer's metric scores them all), m.
    pub fn max_difference_m(&self, a: &PositionTrace, b: &PositionTrace) -> f64 {
        a.ned_m
            .iter()
            .zip(&b.ned_m)
            .map(|(p, q)| (p[0] - q[0]).hypot(p[1] - q[1]))
            .fold(0.0, f64::max)
    }
}

/// One walk through the running processes.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LiveWalk {
    /// Our metric on the in-process run this repeats (the held-out rins setting), m.
    pub offline_rmse_m: f64,
    /// The peer's metric on it, m.
    pub offline_armse_m: f64,
    /// Our metric on the running navigator's positions, m.
    pub live_rmse_m: f64,
    /// The peer's metric on them, m.
    pub live_armse_m: f64,
    /// Largest horizontal position difference to the in-process run, m.
    pub live_vs_offline_max_diff_m: f64,
    /// The same against the pipeline's library code in this process (fusion, altimeter,
    /// navigator lanes: `rins replay --offline`) fed the same frames: the processes' own share, m.
    pub live_vs_same_input_max_diff_m: f64,
    /// The difference the input makes in process: the run fed what fusion makes of the counts
    /// against the run on the recorded samples, m.
    pub quantisation_max_diff_m: f64,
    /// Samples the live navigator aligned later (+) or earlier (−) than the in-process one.
    pub live_alignment_offset_samples: i64,
    /// Samples after the alignment with no live position.
    pub live_samples_missing: usize,
    /// Fusion's fault events seen live (a channel changing state).
    pub live_fdi_events: u64,
    /// Channels fusion excluded at some time during the walk.
    pub live_excluded_channels: Vec<String>,
}

/// Every walk through the running processes.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LiveWalkSummary {
    /// What the processes were fed.
    pub live_input: String,
    /// Mean over the walks of the live RMSE, m.
    pub live_mean_rmse_m: f64,
    /// Mean over the walks of the live ARMSE, m.
    pub live_mean_armse_m: f64,
    /// The largest position difference to the in-process runs over every walk, m.
    pub live_vs_offline_max_diff_m: f64,
    /// The same against the pipeline's library code in process on the same frames, m.
    pub live_vs_same_input_max_diff_m: f64,
    /// The largest difference the input makes in process, m.
    pub quantisation_max_diff_m: f64,
    /// Samples missing live, over every walk.
    pub live_samples_missing: usize,
    /// Walks with a channel excluded live.
    pub walks_with_live_exclusions: usize,
}

/// The summary of the per-walk live figures.
pub fn summarise(input: &str, walks: &[LiveWalk]) -> LiveWalkSummary {
    let max = |f: fn(&LiveWalk) -> f64| walks.iter().map(f).fold(0.0, f64::max);
    LiveWalkSummary {
        live_input: input.to_string(),
        live_mean_rmse_m: super::mean(walks.iter().map(|w| w.live_rmse_m)),
        live_mean_armse_m: super::mean(walks.iter().map(|w| w.live_armse_m)),
        live_vs_offline_max_diff_m: max(|w| w.live_vs_offline_max_diff_m),
        live_vs_same_input_max_diff_m: max(|w| w.live_vs_same_input_max_diff_m),
        quantisation_max_diff_m: max(|w| w.quantisation_max_diff_m),
        live_samples_missing: walks.iter().map(|w| w.live_samples_missing).sum(),
        walks_with_live_exclusions: walks
            .iter()
            .filter(|w| !w.live_excluded_channels.is_empty())
            .count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn walk(n: usize) -> ScoredWalk {
        let samples = (0..n)
            .map(|j| FootSample {
                t_s: j as f64 / 100.0,
                gyro_rps: [0.0; 3],
                accel_mps2: [0.0, 0.0, -9.81],
            })
            .collect();
        let mut config = rins_navigator::NavigatorConfig::default().aided_config();
        config.origin = [0.8, 0.15, 488.0];
        ScoredWalk {
            trial: FootTrial {
                name: "w".into(),
                path: "w.csv".into(),
                samples,
                truth_m: None,
                peer: None,
                dropped_duplicates: 0,
                turned_over: false,
                rate_hz: 100.0,
            },
            truth: (0..n).map(|j| [0.01 * j as f64, 0.0, 0.0]).collect(),
            config,
            run: FootRun::default(),
        }
    }

    /// A published position 1 m north and 2 m east of the origin, as latitude and longitude.
    fn geodetic(north: f64, east: f64, config: &AidedConfig) -> [f64; 3] {
        let [lat0, lon0, alt0] = config.origin;
        let rn = meridian_radius(lat0) + alt0;
        let re = prime_vertical_radius(lat0) + alt0;
        [lat0 + north / rn, lon0 + east / (re * lat0.cos()), alt0]
    }

    #[test]
    fn published_positions_land_on_their_samples_and_gaps_hold_the_last() {
        let w = walk(6);
        let p = |n, e| geodetic(n, e, &w.config);
        let trace = w.trace_from([(2, p(1.0, 2.0)), (3, p(1.5, 2.0)), (5, p(2.0, 2.0))]);
        assert_eq!(trace.aligned_at, Some(2));
        assert_eq!(trace.missing, 1, "sample 4");
        let north: Vec<f64> = trace.ned_m.iter().map(|q| q[0]).collect();
        let want = [0.0, 0.0, 1.0, 1.5, 1.5, 2.0];
        for (got, want) in north.iter().zip(want) {
            // The conversion is the in-process run's, inverted exactly up to rounding.
            assert!((got - want).abs() < 1e-9, "{north:?}");
        }
        assert!(
            trace
                .ned_m
                .iter()
                .skip(2)
                .all(|q| (q[1] - 2.0).abs() < 1e-9)
        );
    }

    #[test]
    fn a_trace_equal_to_the_truth_scores_zero_and_differences_are_horizontal() {
        let w = walk(50);
        let truth = PositionTrace {
            ned_m: w.truth.clone(),
            aligned_at: Some(0),
            missing: 0,
        };
        let s = w.score(&truth);
        assert!(s.armse_m.abs() < 1e-9 && s.rmse_2d_m.abs() < 1e-9, "{s:?}");
        let mut moved = truth.clone();
        moved.ned_m[10] = [moved.ned_m[10][0] + 0.003, 0.004, 7.0];
        assert!((w.max_difference_m(&truth, &moved) - 0.005).abs() < 1e-12);
    }
}
