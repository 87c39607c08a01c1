//! `rins eval xio FILE…`: closed-loop walks, scored by the distance between where the walk
//! starts and where it ends.

use std::path::{Path, PathBuf};

use anyhow::{Result, anyhow};
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use super::metrics::path_length_2d;
use super::plot::{TrialPlot, draw_trial};
use super::reference::{ReferenceConfig, run_reference};
use super::run::{run_trial, run_trial_smoothed};
use super::{FootMethod, Skipped, columns};
use crate::datasets::foot::{FootTrial, PeerResult};
use crate::datasets::xio;
use crate::integrity_tally::IntegritySummary;

/// One closed-loop walk's figures.
#[derive(Debug, Clone, Serialize)]
pub struct XioWalk {
    /// The trial's name.
    pub trial: String,
    /// Length of the recording, s.
    pub seconds: f64,
    /// Distance between the start and end positions (3-D), m.
    pub end_error_m: f64,
    /// Horizontal distance walked (through the foot-down positions), m.
    pub distance_m: f64,
    /// End error as a percentage of the distance walked.
    pub pct_distance: f64,
    /// The peer's end error for this walk, m, when known.
    pub peer_end_error_m: Option<f64>,
    /// Rows the loader dropped because their time equalled the previous kept row's.
    pub dropped_duplicate_rows: usize,
    /// Fraction of the samples the stance detector fired on, 0..=1.
    pub stance_fraction: f64,
    /// Zero-velocity updates the filter's χ² gate rejected (rins only).
    pub zupt_rejected: u64,
    /// How much of the walk the navigator judged usable (rins only).
    pub integrity: Option<IntegritySummary>,
    /// With `--smooth`: the end error of the smoothed trajectory, m (start and end both
    /// smoothed; the end has no future, so only the start moves).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub smoothed_end_error_m: Option<f64>,
    /// With `--smooth`: the smoothed end error as a percentage of the distance walked.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub smoothed_pct_distance: Option<f64>,
}

/// The closed-loop evaluation of every walk given.
#[derive(Debug, Clone, Serialize)]
pub struct XioReport {
    /// The estimator evaluated.
    pub method: FootMethod,
    /// Every walk's figures, in the order given.
    pub trials: Vec<XioWalk>,
    /// Files that could not be evaluated.
    pub skipped: Vec<Skipped>,
    /// The first walk's end error, m (NaN without walks): the figure of a one-file run.
    pub end_error_m: f64,
    /// The first walk's end error as a percentage of its distance (NaN without walks).
    pub pct_distance: f64,
    /// With `--smooth`: the first walk's smoothed end error, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub smoothed_end_error_m: Option<f64>,
}

/// Positions per sample from the navigator's alignment on (or from the first sample for the
/// reference), stance flags, and the rins-only extras.
struct Walked {
    positions: Vec<[f64; 3]>,
    /// The smoothed positions on the same samples (rins with `smooth` only).
    smoothed: Option<Vec<[f64; 3]>>,
    stance: Vec<bool>,
    foot_down: Vec<[f64; 3]>,
    zupt_rejected: u64,
    integrity: Option<IntegritySummary>,
}

fn walk(
    trial: &FootTrial,
    config: &AidedConfig,
    method: FootMethod,
    smooth: bool,
) -> Result<Walked> {
    match method {
        FootMethod::Rins => {
            let run = if smooth {
                run_trial_smoothed(trial, config)
            } else {
                run_trial(trial, config)
            };
            let start = run.aligned_at.ok_or_else(|| {
                anyhow!(
                    "{}: the navigator never aligned (the recording must start with the foot still)",
                    trial.name
                )
            })?;
            Ok(Walked {
                smoothed: smooth.then(|| run.smoothed_ned_m[start..].to_vec()),
                positions: run.ned_m[start..].to_vec(),
                stance: run.stance[start..].to_vec(),
                foot_down: run.foot_down_m,
                zupt_rejected: run.zupt_rejected,
                integrity: Some(run.integrity.summary()),
            })
        }
        FootMethod::Reference => {
            let (accel, gyro) = columns(trial);
            // The method integrates at a fixed step: this walk's own sample interval.
            let config = ReferenceConfig {
                dt_s: 1.0 / trial.rate_hz,
                ..ReferenceConfig::default()
            };
            let run = run_reference(&accel, &gyro, &config);
            let foot_down = (0..run.stance.len())
                .filter(|&k| run.stance[k] && (k == 0 || !run.stance[k - 1]))
                .map(|k| run.position_m[k])
                .collect();
            if smooth {
                return Err(anyhow!(
                    "{}: --smooth needs the rins method (the reference method keeps no filter \
                     history)",
                    trial.name
                ));
            }
            Ok(Walked {
                smoothed: None,
                positions: run.position_m,
                stance: run.stance,
                foot_down,
                zupt_rejected: 0,
                integrity: None,
            })
        }
    }
}

/// The closed-loop evaluation of one walk.
pub fn evaluate_xio_walk(
    trial: &FootTrial,
    config: &AidedConfig,
    method: FootMethod,
    plot_dir: Option<&Path>,
    smooth: bool,
) -> Result<XioWalk> {
    let walked = walk(trial, config, method, smooth)?;
    let end_error = end_to_start(&walked.positions);
    let distance = path_length_2d(&walked.foot_down);
    let smoothed_end_error = walked.smoothed.as_deref().map(end_to_start);
    if let Some(dir) = plot_dir {
        let offset = trial.samples.len() - walked.positions.len();
        let times: Vec<f64> = trial.samples[offset..].iter().map(|s| s.t_s).collect();
        draw_trial(
            dir,
            &TrialPlot {
                name: &trial.name,
                method,
                t_s: &times,
                estimate: &walked.positions,
                rotation_rad: 0.0,
                truth: None,
                stance: &walked.stance,
            },
        )?;
    }
    Ok(XioWalk {
        trial: trial.name.clone(),
        seconds: trial.duration_s(),
        end_error_m: end_error,
        distance_m: distance,
        pct_distance: 100.0 * end_error / distance.max(f64::MIN_POSITIVE),
        peer_end_error_m: match trial.peer {
            Some(PeerResult::EndErrorM(e)) => Some(e),
            _ => None,
        },
        dropped_duplicate_rows: trial.dropped_duplicates,
        stance_fraction: walked.stance.iter().filter(|&&s| s).count() as f64
            / walked.stance.len().max(1) as f64,
        zupt_rejected: walked.zupt_rejected,
        integrity: walked.integrity,
        smoothed_end_error_m: smoothed_end_error,
        smoothed_pct_distance: smoothed_end_error
            .map(|e| 100.0 * e / distance.max(f64::MIN_POSITIVE)),
    })
}

/// Distance between the first and the last position (3-D), m; 0 without positions.
fn end_to_start(positions: &[[f64; 3]]) -> f64 {
    let first = positions.first().copied().unwrap_or([0.0; 3]);
    let last = positions.last().copied().unwrap_or(first);
    (0..3)
        .map(|k| (last[k] - first[k]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// Each walk file; `progress(done, total)` after each. A file that cannot be read or walked is
/// listed in `skipped` and the others go on.
pub fn evaluate_xio(
    files: &[PathBuf],
    config: &AidedConfig,
    method: FootMethod,
    plot_dir: Option<&Path>,
    smooth: bool,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<XioReport> {
    progress(0, files.len());
    let mut trials = Vec::with_capacity(files.len());
    let mut skipped = Vec::new();
    for (i, file) in files.iter().enumerate() {
        let outcome = xio::load_walk(file)
            .map_err(anyhow::Error::from)
            .and_then(|trial| evaluate_xio_walk(&trial, config, method, plot_dir, smooth));
        match outcome {
            Ok(w) => trials.push(w),
            Err(e) => skipped.push(Skipped {
                file: file.display().to_string(),
                reason: format!("{e:#}"),
            }),
        }
        progress(i + 1, files.len());
    }
    if trials.is_empty() {
        return Err(anyhow!(
            "eval xio: no walk could be evaluated: {}",
            skipped.first().map_or("", |s| s.reason.as_str())
        ));
    }
    Ok(XioReport {
        method,
        end_error_m: trials[0].end_error_m,
        pct_distance: trials[0].pct_distance,
        smoothed_end_error_m: trials[0].smoothed_end_error_m,
        trials,
        skipped,
    })
}
