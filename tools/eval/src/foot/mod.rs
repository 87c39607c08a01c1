//! Foot-mounted (pedestrian profile) evaluation on recorded walks, with the navigator library
//! and no IPC: `rins eval pyshoe DIR` (2-D RMSE against Vicon per trial) and `rins eval xio FILE…`
//! (end-point error of closed-loop walks). One configuration — the pedestrian profile — for
//! every trial.

pub mod metrics;
pub mod report;
pub mod run;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use crate::datasets::foot::{FootTrial, PeerResult};
use crate::datasets::{pyshoe, xio};
use crate::integrity_tally::IntegritySummary;
use metrics::{aligned_rmse_2d, path_length_2d};
use run::{FootRun, run_trial};

/// One pyshoe trial's figures.
#[derive(Debug, Clone, Serialize)]
pub struct PyshoeTrial {
    /// The trial's name.
    pub trial: String,
    /// Length of the recording, s.
    pub seconds: f64,
    /// 2-D position RMSE against the Vicon truth from alignment on, after fitting the start and
    /// the initial heading, m.
    pub rmse_2d_m: f64,
    /// The peer's best 2-D RMSE (its detector threshold tuned for this trial), when known.
    pub peer_rmse_2d_m: Option<f64>,
    /// Initial heading fitted to the truth, degrees.
    pub heading_fit_deg: f64,
    /// Fraction of the samples the stance detector fired on, 0..=1.
    pub stance_fraction: f64,
    /// Zero-velocity updates the filter's χ² gate rejected.
    pub zupt_rejected: u64,
    /// How much of the walk the navigator judged usable.
    pub integrity: IntegritySummary,
}

/// The pyshoe evaluation of a whole directory.
#[derive(Debug, Clone, Serialize)]
pub struct PyshoeReport {
    /// Every trial's figures, in file order.
    pub trials: Vec<PyshoeTrial>,
    /// Mean of the trials' 2-D RMSE, m (NaN without trials).
    pub mean_rmse_m: f64,
    /// Mean of the peer's per-trial RMSE, m; only when every trial has the peer's figure.
    pub peer_mean_rmse_m: Option<f64>,
}

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
    /// Zero-velocity updates the filter's χ² gate rejected.
    pub zupt_rejected: u64,
    /// How much of the walk the navigator judged usable.
    pub integrity: IntegritySummary,
}

/// The closed-loop evaluation of every walk given.
#[derive(Debug, Clone, Serialize)]
pub struct XioReport {
    /// Every walk's figures, in the order given.
    pub trials: Vec<XioWalk>,
}

fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

fn seconds(trial: &FootTrial) -> f64 {
    match (trial.samples.first(), trial.samples.last()) {
        (Some(a), Some(b)) => b.t_s - a.t_s,
        _ => 0.0,
    }
}

fn aligned(trial: &FootTrial, run: &FootRun) -> Result<usize> {
    run.aligned_at.ok_or_else(|| {
        anyhow!(
            "{}: the navigator never aligned (the recording must start with the foot still)",
            trial.name
        )
    })
}

/// The pyshoe evaluation of one trial.
pub fn evaluate_pyshoe_trial(trial: &FootTrial, config: &AidedConfig) -> Result<PyshoeTrial> {
    let truth = trial
        .truth_m
        .as_ref()
        .ok_or_else(|| anyhow!("{}: no truth positions", trial.name))?;
    let run = run_trial(trial, config);
    let start = aligned(trial, &run)?;
    // North, east of the estimate against the export's Vicon x, y. With the Vicon z up, that pair
    // is mirrored (x, y, up is left-handed), so the export's horizontal axes do not form the
    // right-handed frame their z suggests: matched as east, north, every trial's shape comes out
    // mirrored and the rotation fit leaves metres of error; as north, east it fits within
    // centimetres. Only a rotation is fitted, never a reflection, so this pairing is fixed for the
    // whole data set, not chosen per trial.
    let estimate: Vec<[f64; 2]> = run.ned_m[start..].iter().map(|p| [p[0], p[1]]).collect();
    let reference: Vec<[f64; 2]> = truth[start..].iter().map(|p| [p[0], p[1]]).collect();
    let (rmse, theta) = aligned_rmse_2d(&estimate, &reference);
    Ok(PyshoeTrial {
        trial: trial.name.clone(),
        seconds: seconds(trial),
        rmse_2d_m: rmse,
        peer_rmse_2d_m: match trial.peer {
            Some(PeerResult::Rmse2dM(r)) => Some(r),
            _ => None,
        },
        heading_fit_deg: theta.to_degrees(),
        stance_fraction: run.stance_samples as f64 / trial.samples.len().max(1) as f64,
        zupt_rejected: run.zupt_rejected,
        integrity: run.integrity.summary(),
    })
}

/// Every trial of a pyshoe directory; `progress(done, total)` after each.
pub fn evaluate_pyshoe(
    dir: &Path,
    config: &AidedConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<PyshoeReport> {
    let files = pyshoe::list_trials(dir)
        .with_context(|| format!("eval pyshoe: cannot list {}", dir.display()))?;
    if files.is_empty() {
        return Err(anyhow!("eval pyshoe: no *.csv trials in {}", dir.display()));
    }
    progress(0, files.len());
    let mut trials = Vec::with_capacity(files.len());
    for (i, file) in files.iter().enumerate() {
        let trial = pyshoe::load_trial(file).context("eval pyshoe")?;
        trials.push(evaluate_pyshoe_trial(&trial, config).context("eval pyshoe")?);
        progress(i + 1, files.len());
    }
    let peers: Vec<f64> = trials.iter().filter_map(|t| t.peer_rmse_2d_m).collect();
    Ok(PyshoeReport {
        mean_rmse_m: mean(trials.iter().map(|t| t.rmse_2d_m)),
        peer_mean_rmse_m: (peers.len() == trials.len()).then(|| mean(peers.into_iter())),
        trials,
    })
}

/// The closed-loop evaluation of one walk.
pub fn evaluate_xio_walk(trial: &FootTrial, config: &AidedConfig) -> Result<XioWalk> {
    let run = run_trial(trial, config);
    let start = aligned(trial, &run)?;
    let first = run.ned_m[start];
    let last = run.ned_m.last().copied().unwrap_or(first);
    let end_error = (0..3)
        .map(|k| (last[k] - first[k]).powi(2))
        .sum::<f64>()
        .sqrt();
    let distance = path_length_2d(&run.foot_down_m);
    Ok(XioWalk {
        trial: trial.name.clone(),
        seconds: seconds(trial),
        end_error_m: end_error,
        distance_m: distance,
        pct_distance: 100.0 * end_error / distance.max(f64::MIN_POSITIVE),
        peer_end_error_m: match trial.peer {
            Some(PeerResult::EndErrorM(e)) => Some(e),
            _ => None,
        },
        dropped_duplicate_rows: trial.dropped_duplicates,
        stance_fraction: run.stance_samples as f64 / trial.samples.len().max(1) as f64,
        zupt_rejected: run.zupt_rejected,
        integrity: run.integrity.summary(),
    })
}

/// Each walk file; `progress(done, total)` after each.
pub fn evaluate_xio(
    files: &[PathBuf],
    config: &AidedConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<XioReport> {
    progress(0, files.len());
    let mut trials = Vec::with_capacity(files.len());
    for (i, file) in files.iter().enumerate() {
        let trial = xio::load_walk(file).context("eval xio")?;
        trials.push(evaluate_xio_walk(&trial, config).context("eval xio")?);
        progress(i + 1, files.len());
    }
    Ok(XioReport { trials })
}
