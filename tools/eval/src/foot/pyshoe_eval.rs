//! `rins eval pyshoe DIR`: every trial through rins and through the peer's method, each scored on
//! our metric and on the peer's, beside the peer's own per-trial-tuned figures.

use std::convert::Infallible;
use std::path::Path;

use anyhow::{Context, Result, anyhow};
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use super::detectors::{DetectorFigure, compare, comparison_candidates};
use super::live::{LiveWalk, LiveWalkSummary, ScoredWalk, score_positions};
use super::metrics::{aligned_rmse_2d, peer_armse_2d, round_mm};
use super::plot::{TrialPlot, draw_trial};
use super::reference::{ReferenceConfig, run_with_statistic, shoe_statistic};
use super::run::{FootRun, run_trial, run_trial_smoothed};
use super::strides::{StrideAnalysis, analyse};
use super::{
    FootMethod, Skipped, columns, mean, reference_thresholds, rins_candidates, stance_threshold,
};
use crate::datasets::foot::{FootTrial, PeerResult};
use crate::datasets::pyshoe;
use crate::integrity_tally::IntegritySummary;
use crate::leave_one_out::{choose_on_all, choose_without_each};
use crate::parallel::run_indexed;

/// Threads the candidate settings of one trial are scored on: the machine's.
fn threads() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// One pyshoe trial's figures.
#[derive(Debug, Clone, Serialize)]
pub struct PyshoeTrial {
    /// The trial's name.
    pub trial: String,
    /// Length of the recording, s.
    pub seconds: f64,
    /// The peer's metric for the evaluated method, its threshold chosen on the other trials, m.
    pub armse_m: f64,
    /// Our metric for the evaluated method: 2-D RMSE from the navigator's alignment on, after a
    /// least-squares fit of the start and the initial heading, m.
    pub rmse_2d_m: f64,
    /// rins on the peer's metric, threshold chosen on the other trials, m.
    pub rins_armse_m: f64,
    /// rins on the peer's metric with the profile exactly as configured, m.
    pub rins_profile_armse_m: f64,
    /// The SHOE threshold rins was scored with here.
    pub rins_threshold: f64,
    /// The stance threshold's raise factor rins was scored with here (1: never raised).
    pub rins_raise_factor: f64,
    /// The stance threshold's gait exponent rins was scored with here (0: a fixed threshold).
    pub rins_gait_exponent: f64,
    /// The gyro lag rins was scored with here, s.
    pub rins_gyro_lag_s: f64,
    /// The peer's method on the peer's metric, threshold chosen on the other trials, m.
    pub reference_armse_m: f64,
    /// The threshold the peer's method was scored with here.
    pub reference_threshold: f64,
    /// The peer's best figure on this trial (its threshold and detector tuned for it), m.
    pub peer_armse_m: Option<f64>,
    /// The peer's SHOE figure on this trial (threshold tuned for it), m.
    pub peer_shoe_armse_m: Option<f64>,
    /// The evaluated method beat the peer's best on this trial (both rounded to 1 mm as the
    /// peer reports).
    pub better_than_peer: Option<bool>,
    /// Rotation the peer's alignment applied to the estimate, degrees.
    pub heading_deg: f64,
    /// Stride lengths and stance timing against the truth.
    pub strides: StrideAnalysis,
    /// Fraction of the samples in stance, 0..=1.
    pub stance_fraction: f64,
    /// Zero-velocity updates the filter's χ² gate rejected (rins only).
    pub zupt_rejected: u64,
    /// How much of the walk the navigator judged usable (rins only).
    pub integrity: Option<IntegritySummary>,
    /// With `--smooth`: the held-out rins run smoothed after the fact (Rauch–Tung–Striebel over
    /// the filter's history), on the peer's metric, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub smoothed_armse_m: Option<f64>,
    /// The held-out rins run repeated through the running processes (`--live`).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub live: Option<LiveWalk>,
}

/// How `rins eval pyshoe` runs.
#[derive(Debug, Clone, Copy, Default)]
pub struct PyshoeOptions<'a> {
    /// The estimator of the per-trial figures, the means and the plots.
    pub method: FootMethod,
    /// One PNG per trial into this directory.
    pub plot_dir: Option<&'a Path>,
    /// Also smooth each held-out rins run and report it beside the causal figure.
    pub smooth: bool,
}

/// The pyshoe evaluation of a whole directory.
#[derive(Debug, Clone, Serialize)]
pub struct PyshoeReport {
    /// The estimator of `armse_m`, `rmse_2d_m`, the strides and the plots.
    pub method: FootMethod,
    /// Every evaluated trial, in file order.
    pub trials: Vec<PyshoeTrial>,
    /// Files that could not be evaluated.
    pub skipped: Vec<Skipped>,
    /// Mean of our metric, m.
    pub mean_rmse_m: f64,
    /// Mean of the peer's metric for the evaluated method (held-out thresholds), m.
    pub mean_armse_m: f64,
    /// Mean of the peer's best per-trial-tuned figures, m (when every trial has one).
    pub peer_mean_armse_m: Option<f64>,
    /// Mean of the peer's per-trial-tuned SHOE figures, m (when every trial has one).
    pub peer_shoe_mean_armse_m: Option<f64>,
    /// Trials on which the evaluated method beat the peer's best (same metric, 1 mm rounding).
    pub trials_better_than_peer: usize,
    /// Trials with a peer figure.
    pub trials_compared: usize,
    /// rins, held-out thresholds, m.
    pub rins_mean_armse_m: f64,
    /// rins with the profile as configured, m.
    pub rins_profile_mean_armse_m: f64,
    /// The peer's method with one threshold for all trials, held out, m.
    pub reference_mean_armse_m: f64,
    /// The SHOE threshold of rins chosen on every trial (what a configuration would ship).
    pub rins_threshold_all: f64,
    /// The raise factor of rins chosen on every trial.
    pub rins_raise_factor_all: f64,
    /// The gait exponent of rins chosen on every trial.
    pub rins_gait_exponent_all: f64,
    /// The gyro lag of rins chosen on every trial, s.
    pub rins_gyro_lag_s_all: f64,
    /// The threshold of the peer's method chosen on every trial.
    pub reference_threshold_all: f64,
    /// Mean over the trials of Σ estimated / Σ true stride length.
    pub mean_stride_length_ratio: f64,
    /// The stance detectors side by side, each cross-validated the same way.
    pub detectors: Vec<DetectorFigure>,
    /// With `--smooth`: mean of the smoothed held-out rins runs on the peer's metric, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub smoothed_mean_armse_m: Option<f64>,
    /// With `--smooth`: trials on which the smoothed run beat the peer's best (1 mm rounding).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub smoothed_trials_better_than_peer: Option<usize>,
    /// Every held-out rins run repeated through the running processes (`--live`).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub live: Option<LiveWalkSummary>,
}

/// What one estimator produced on one trial with one setting.
struct Scored {
    armse_m: f64,
    rmse_2d_m: f64,
    rotation_rad: f64,
    ned_m: Vec<[f64; 3]>,
    stance: Vec<bool>,
    zupt_rejected: u64,
    integrity: Option<IntegritySummary>,
}

fn horizontal(points: &[[f64; 3]]) -> Vec<[f64; 2]> {
    points.iter().map(|p| [p[0], p[1]]).collect()
}

// The estimate's first two axes (north, east) against the export's Vicon x, y: see
// [`score_positions`].
fn score_rins(trial: &FootTrial, truth: &[[f64; 3]], config: &AidedConfig) -> Scored {
    score_run(run_trial(trial, config), truth)
}

fn score_run(run: FootRun, truth: &[[f64; 3]]) -> Scored {
    let score = score_positions(&run.ned_m, run.aligned_at, truth);
    Scored {
        armse_m: score.armse_m,
        rmse_2d_m: score.rmse_2d_m,
        rotation_rad: score.rotation_rad,
        zupt_rejected: run.zupt_rejected,
        integrity: Some(run.integrity.summary()),
        ned_m: run.ned_m,
        stance: run.stance,
    }
}

fn score_reference(
    trial: &FootTrial,
    truth: &[[f64; 3]],
    statistic: &[f64],
    threshold: f64,
) -> Scored {
    let (accel, gyro) = columns(trial);
    let config = ReferenceConfig {
        threshold,
        ..ReferenceConfig::default()
    };
    let run = run_with_statistic(&accel, &gyro, statistic, &config);
    let (estimate, truth_xy) = (horizontal(&run.position_m), horizontal(truth));
    let peer = peer_armse_2d(&estimate, &truth_xy);
    Scored {
        armse_m: peer.armse_m,
        rmse_2d_m: aligned_rmse_2d(&estimate, &truth_xy).0,
        rotation_rad: peer.rotation_rad,
        zupt_rejected: 0,
        integrity: None,
        ned_m: run.position_m,
        stance: run.stance,
    }
}

/// A loaded trial with its truth and the reference detector's statistic.
struct Loaded {
    trial: FootTrial,
    truth: Vec<[f64; 3]>,
    statistic: Vec<f64>,
}

fn load(file: &Path) -> Result<Loaded> {
    let trial = pyshoe::load_trial(file)?;
    let truth = trial
        .truth_m
        .clone()
        .ok_or_else(|| anyhow!("{}: no truth positions", trial.name))?;
    let (accel, gyro) = columns(&trial);
    let r = ReferenceConfig::default();
    let statistic = shoe_statistic(
        &accel,
        &gyro,
        r.window,
        r.detector_sigma_a,
        r.detector_sigma_w,
        r.g,
    );
    Ok(Loaded {
        trial,
        truth,
        statistic,
    })
}

/// Every trial of a pyshoe directory; `progress(done, total)` as the runs complete. Plots go to
/// `plot_dir` when given.
pub fn evaluate_pyshoe(
    dir: &Path,
    config: &AidedConfig,
    options: PyshoeOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<PyshoeReport> {
    Ok(evaluate(dir, config, options, false, progress)?.0)
}

/// As [`evaluate_pyshoe`], with each trial's held-out rins run kept (in the report's trial
/// order) for the running service to repeat.
pub fn evaluate_pyshoe_with_runs(
    dir: &Path,
    config: &AidedConfig,
    options: PyshoeOptions,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(PyshoeReport, Vec<ScoredWalk>)> {
    evaluate(dir, config, options, true, progress)
}

fn evaluate(
    dir: &Path,
    config: &AidedConfig,
    options: PyshoeOptions,
    keep_runs: bool,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(PyshoeReport, Vec<ScoredWalk>)> {
    let PyshoeOptions {
        method,
        plot_dir,
        smooth,
    } = options;
    let files = pyshoe::list_trials(dir)
        .with_context(|| format!("eval pyshoe: cannot list {}", dir.display()))?;
    if files.is_empty() {
        return Err(anyhow!("eval pyshoe: no *.csv trials in {}", dir.display()));
    }
    let mut skipped = Vec::new();
    let mut loaded = Vec::new();
    for file in &files {
        match load(file) {
            Ok(l) => loaded.push(l),
            Err(e) => skipped.push(Skipped {
                file: file.display().to_string(),
                reason: format!("{e:#}"),
            }),
        }
    }
    if loaded.is_empty() {
        return Err(anyhow!(
            "eval pyshoe: no trial of {} could be read: {}",
            dir.display(),
            skipped.first().map_or("", |s| s.reason.as_str())
        ));
    }
    // The SHOE grid (what the headline chooses among) first, then the other detectors compared.
    let candidates = comparison_candidates(config);
    let every: Vec<AidedConfig> = candidates.iter().map(|c| c.1).collect();
    let rins = &every[..rins_candidates(config).len()];
    let thresholds = reference_thresholds();
    let total = loaded.len() * (every.len() + thresholds.len() + 2);
    let mut done = 0;
    progress(done, total);
    let mut all_scores: Vec<Vec<f64>> = Vec::with_capacity(loaded.len());
    let mut reference_scores = Vec::with_capacity(loaded.len());
    let mut profile_scores = Vec::with_capacity(loaded.len());
    for l in &loaded {
        let Ok(row) = run_indexed(
            every.len(),
            threads(),
            |k| Ok::<f64, Infallible>(score_rins(&l.trial, &l.truth, &every[k]).armse_m),
            |_, _| {},
        );
        done += every.len();
        progress(done, total);
        profile_scores.push(score_rins(&l.trial, &l.truth, config).armse_m);
        all_scores.push(row);
        reference_scores.push(
            thresholds
                .iter()
                .map(|&t| score_reference(&l.trial, &l.truth, &l.statistic, t).armse_m)
                .collect::<Vec<f64>>(),
        );
        done += thresholds.len() + 1;
        progress(done, total);
    }
    // The choice minimises the geometric mean of the ARMSE over the training trials: one trial
    // that diverges under every setting (metres, where the others are centimetres) would
    // otherwise decide alone.
    let logs = |m: &[Vec<f64>]| -> Vec<Vec<f64>> {
        m.iter()
            .map(|r| r.iter().map(|v| v.max(1e-6).ln()).collect())
            .collect()
    };
    let rins_scores: Vec<Vec<f64>> = all_scores
        .iter()
        .map(|row| row[..rins.len()].to_vec())
        .collect();
    let (rins_logs, reference_logs) = (logs(&rins_scores), logs(&reference_scores));
    let peers: Vec<Option<f64>> = loaded
        .iter()
        .map(|l| match l.trial.peer {
            Some(PeerResult::Armse2d { best_m, .. }) => Some(best_m),
            _ => None,
        })
        .collect();
    let detectors = compare(&candidates, &all_scores, &logs(&all_scores), &peers);
    let rins_choice = choose_without_each(&rins_logs);
    let reference_choice = choose_without_each(&reference_logs);
    let mut trials = Vec::with_capacity(loaded.len());
    let mut runs = Vec::new();
    for (i, l) in loaded.iter().enumerate() {
        let rins_config = &rins[rins_choice[i]];
        if keep_runs {
            runs.push(ScoredWalk::new(
                l.trial.clone(),
                l.truth.clone(),
                *rins_config,
            ));
        }
        let reference_threshold = thresholds[reference_choice[i]];
        // The held-out rins run, once: scored, and smoothed when asked.
        let held_out = (method == FootMethod::Rins || smooth).then(|| {
            if smooth {
                run_trial_smoothed(&l.trial, rins_config)
            } else {
                run_trial(&l.trial, rins_config)
            }
        });
        let smoothed_armse_m = held_out
            .as_ref()
            .filter(|_| smooth)
            .map(|run| score_positions(&run.smoothed_ned_m, run.aligned_at, &l.truth).armse_m);
        // With rins evaluated the held-out run is always there.
        let scored = match held_out.filter(|_| method == FootMethod::Rins) {
            Some(run) => score_run(run, &l.truth),
            None => score_reference(&l.trial, &l.truth, &l.statistic, reference_threshold),
        };
        let (peer, peer_shoe) = match l.trial.peer {
            Some(PeerResult::Armse2d { best_m, shoe_m }) => (Some(best_m), shoe_m),
            _ => (None, None),
        };
        let times: Vec<f64> = l.trial.samples.iter().map(|s| s.t_s).collect();
        if let Some(dir) = plot_dir {
            draw_trial(
                dir,
                &TrialPlot {
                    name: &l.trial.name,
                    method,
                    t_s: &times,
                    estimate: &scored.ned_m,
                    rotation_rad: scored.rotation_rad,
                    truth: Some(&l.truth),
                    stance: &scored.stance,
                },
            )?;
        }
        trials.push(PyshoeTrial {
            trial: l.trial.name.clone(),
            seconds: l.trial.duration_s(),
            armse_m: scored.armse_m,
            rmse_2d_m: scored.rmse_2d_m,
            rins_armse_m: rins_scores[i][rins_choice[i]],
            rins_profile_armse_m: profile_scores[i],
            rins_threshold: stance_threshold(rins_config),
            rins_raise_factor: rins_config.stance.raise_factor,
            rins_gait_exponent: rins_config.stance.gait_exponent,
            rins_gyro_lag_s: rins_config.gyro_lag_s,
            reference_armse_m: reference_scores[i][reference_choice[i]],
            reference_threshold,
            peer_armse_m: peer,
            peer_shoe_armse_m: peer_shoe,
            better_than_peer: peer.map(|p| round_mm(scored.armse_m) < p),
            heading_deg: scored.rotation_rad.to_degrees(),
            strides: analyse(&scored.ned_m, &scored.stance, &l.truth, &times),
            stance_fraction: scored.stance.iter().filter(|&&s| s).count() as f64
                / scored.stance.len().max(1) as f64,
            zupt_rejected: scored.zupt_rejected,
            integrity: scored.integrity,
            smoothed_armse_m,
            live: None,
        });
        done += 1;
        progress(done, total);
    }
    let all = |f: &dyn Fn(&PyshoeTrial) -> Option<f64>| -> Option<f64> {
        let v: Vec<f64> = trials.iter().filter_map(f).collect();
        (v.len() == trials.len()).then(|| mean(v.into_iter()))
    };
    progress(total, total);
    let report = PyshoeReport {
        method,
        mean_rmse_m: mean(trials.iter().map(|t| t.rmse_2d_m)),
        mean_armse_m: mean(trials.iter().map(|t| t.armse_m)),
        peer_mean_armse_m: all(&|t| t.peer_armse_m),
        peer_shoe_mean_armse_m: all(&|t| t.peer_shoe_armse_m),
        trials_better_than_peer: trials
            .iter()
            .filter(|t| t.better_than_peer == Some(true))
            .count(),
        trials_compared: trials.iter().filter(|t| t.peer_armse_m.is_some()).count(),
        rins_mean_armse_m: mean(trials.iter().map(|t| t.rins_armse_m)),
        rins_profile_mean_armse_m: mean(trials.iter().map(|t| t.rins_profile_armse_m)),
        reference_mean_armse_m: mean(trials.iter().map(|t| t.reference_armse_m)),
        rins_threshold_all: stance_threshold(&rins[choose_on_all(&rins_logs)]),
        rins_raise_factor_all: rins[choose_on_all(&rins_logs)].stance.raise_factor,
        rins_gait_exponent_all: rins[choose_on_all(&rins_logs)].stance.gait_exponent,
        rins_gyro_lag_s_all: rins[choose_on_all(&rins_logs)].gyro_lag_s,
        reference_threshold_all: thresholds[choose_on_all(&reference_logs)],
        mean_stride_length_ratio: mean(
            trials
                .iter()
                .map(|t| t.strides.length_ratio)
                .filter(|r| r.is_finite()),
        ),
        smoothed_mean_armse_m: all(&|t| t.smoothed_armse_m),
        detectors,
        smoothed_trials_better_than_peer: smooth.then(|| {
            trials
                .iter()
                .filter(|t| match (t.smoothed_armse_m, t.peer_armse_m) {
                    (Some(s), Some(p)) => round_mm(s) < p,
                    _ => false,
                })
                .count()
        }),
        trials,
        skipped,
        live: None,
    };
    Ok((report, runs))
}
