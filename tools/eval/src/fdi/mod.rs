//! Fault detection and isolation on the four-IMU quadrotor recordings (real rotor vibration),
//! in-process, with every tuned parameter chosen without the flight it is scored on.
//!
//! Redundant configurations built from every flight ([`layout`]):
//! - `pyramid4`: channel i = IMU i projected on the pyramid axis h_i (α = 28.7°, β0 = 45°), one
//!   single-axis channel per IMU as on the product's block (flights with four units);
//! - `stacked12` / `stacked9` / `stacked6`: the units' triads turned into the reference unit's
//!   frame (flights with four, three or two units). A flight with one unit has no redundancy to
//!   monitor: it is listed, not evaluated.
//!
//! What is learnt, and from what:
//! - **Clock offsets between units** (whole rows from |ω| cross-matching, then sub-row lags by
//!   resampling): per flight from its own gyro data, by the loader; they align the recordings
//!   (a single-clock block has none) and no injected fault can reach them.
//! - **Installation rotations and lever arms** ([`learned_geometry`]): from the *other* flights.
//! - **Relative biases** between the units: in the first [`BIAS_WINDOW_S`] of the flight, during
//!   the fuser's learning phase in which no alarm can be raised (what the product does at start).
//! - **Adaptive parity noise**: learnt online by the fuser itself, as in the product.
//! - **Detector settings** (false-alarm probability, detector σ, motion noise fraction, timing
//!   skew; [`candidates`]): chosen leave-one-flight-out ([`cross_validation`]). Every figure of
//!   the report (false alarms, detection, per flight) is the held-out flight's with the setting
//!   chosen on the others; [`roc`] sweeps the false-alarm probability the same way.
//!
//! Pre-processing, the same fixed rules for every flight ([`prepare`]): a 4-row moving average
//! against rotor vibration ([`PREFILTER_ROWS`]), the relative-bias removal, channels → 12-bit
//! counts at the product's converter resolution, so that the fuser's real path runs: calibration,
//! channel health (stuck, saturation) on the counts, parity with persistence, isolation.
//!
//! Faults ([`faults`]) are injected at the middle row of each flight into one channel of one
//! type: dead (valid bit cleared), stuck, bias steps of 5, 10 and 20 σ, a ramp, a noise increase,
//! saturation. The fault-free run is deterministic, so each faulted run starts from a copy of the
//! fault-free fuser at the fault row.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use rins_fusion::FdiConfig;

use crate::datasets::quadrotor::{
    Repairs, SkippedTrial, list_trials, load_trial, nothing_evaluated,
};

pub mod candidates;
pub mod cross_validation;
mod episodes;
pub mod faults;
mod layout;
mod learned_geometry;
mod plot;
mod prepare;
mod report;
pub mod roc;
mod runs;
mod summary;
mod table;
mod tally;

pub use candidates::DetectorSetting;
pub use episodes::AlarmEpisode;
pub use layout::NoiseFit;
pub use plot::draw_roc;
pub use report::{
    ConfigurationSummary, FaultBreakdown, FdiReport, OperatingPoint, TrialReport, to_table,
};
pub use roc::RocPoint;
pub use tally::Tally;

/// What to evaluate: the data set, an optional trial filter, the fault detection settings and
/// the converter resolution of the product.
#[derive(Debug, Clone)]
pub struct FdiRequest {
    /// Data set directory (`<group>/path_<N>/IMU_k.csv`).
    pub dir: PathBuf,
    /// Only trials whose name contains one of these (all when empty).
    pub trials: Vec<String>,
    /// The configured `[fusion.fdi]` (see [`candidates::fusion_config`] for what the evaluation
    /// changes).
    pub fdi: FdiConfig,
    /// Gyro and accelerometer count resolution, rad/s and m/s².
    pub lsb: [f64; 2],
    /// Worker threads for the runs (at least one).
    pub threads: usize,
}

/// Length of the window at the start of each trial over which relative biases are measured, s
/// (inside the fuser's learning phase, [`candidates::LEARNING_S`]).
pub const BIAS_WINDOW_S: f64 = 2.0;
/// Moving average over this many rows (33 ms) before everything else: rotor vibration, which the
/// units see differently (frame flexing, lever arms, residual sub-row lag), dominates the
/// disagreement between IMUs at 120 Hz; averaging over 4 rows cuts the parity noise by about 3
/// (gyro) and 4 (accel). Faults are injected after it, i.e. into the band-limited outputs.
pub const PREFILTER_ROWS: usize = 4;

/// Runs the evaluation; `progress(done, total)` after each flight and setting.
pub fn evaluate(request: &FdiRequest, progress: &mut dyn FnMut(usize, usize)) -> Result<FdiReport> {
    let dir = &request.dir;
    if !dir.is_dir() {
        return Err(anyhow!(
            "eval fdi: data set directory {} does not exist or is not a directory; {}",
            dir.display(),
            crate::data::fetch_hint(dir)
        ));
    }
    let entries = list_trials(dir)
        .with_context(|| format!("eval fdi: cannot list trials in {}", dir.display()))?;
    let entries: Vec<_> = entries
        .into_iter()
        .filter(|e| request.trials.is_empty() || request.trials.iter().any(|t| e.name.contains(t)))
        .collect();
    if entries.is_empty() {
        return Err(anyhow!(
            "eval fdi: no trials (<group>/path_<N>/IMU_k.csv) in {}{}",
            dir.display(),
            if request.trials.is_empty() {
                String::new()
            } else {
                format!(" matching {:?}", request.trials)
            }
        ));
    }
    // Load every flight and estimate its own geometry; a flight that fails is listed, never
    // fatal.
    let mut skipped = Vec::new();
    let mut single_unit = Vec::new();
    let mut loaded = Vec::new();
    let mut own = Vec::new();
    let mut repairs = Repairs::default();
    for entry in &entries {
        let trial = match load_trial(&entry.path) {
            Ok(t) => {
                repairs += t.repairs;
                t
            }
            Err(e) => {
                repairs.trials_failed += 1;
                skipped.push(SkippedTrial {
                    trial: entry.name.clone(),
                    reason: e.to_string(),
                });
                continue;
            }
        };
        if layout::Layout::for_units(trial.imus.len()).is_empty() {
            single_unit.push(SkippedTrial {
                trial: entry.name.clone(),
                reason: format!(
                    "{} unit: no redundancy to monitor (listed, not evaluated)",
                    trial.imus.len()
                ),
            });
            continue;
        }
        match learned_geometry::own_geometry(&trial) {
            Ok(g) => {
                own.push(g);
                loaded.push(trial);
            }
            Err(e) => skipped.push(SkippedTrial {
                trial: entry.name.clone(),
                reason: format!("installation: {e}"),
            }),
        }
    }
    // Every flight in every layout its units allow, with the geometry of the other flights.
    let mut prepared = Vec::new();
    for (i, trial) in loaded.iter().enumerate() {
        let learned = learned_geometry::learned_geometry(&own, i);
        for layout in layout::Layout::for_units(trial.imus.len()) {
            let geometry = layout
                .geometry()
                .build()
                .map_err(|e| anyhow!("eval fdi: {} geometry: {e}", layout.name()))?;
            match prepare::prepare(trial, layout, &geometry, request.lsb, &learned) {
                Ok(p) => prepared.push(table::PreparedFlight {
                    flight: i,
                    trial: trial.name.clone(),
                    layout,
                    geometry,
                    p,
                    flights_pooled: learned.flights_pooled,
                }),
                Err(e) => skipped.push(SkippedTrial {
                    trial: format!("{} ({})", trial.name, layout.name()),
                    reason: format!("{e:#}"),
                }),
            }
        }
    }
    if prepared.is_empty() && single_unit.is_empty() {
        return Err(anyhow!("eval fdi: {}", nothing_evaluated(&skipped)));
    }
    let settings = candidates::grid();
    for layout in [
        layout::Layout::Pyramid4,
        layout::Layout::Stacked { units: 2 },
    ] {
        for s in &settings {
            candidates::fusion_config(&request.fdi, layout, s)
                .validate()
                .map_err(|e| anyhow!("eval fdi: fusion settings {s:?}: {e}"))?;
        }
    }
    let faults = faults::FaultKind::all();
    let table = table::run_table(
        &prepared,
        &request.fdi,
        &settings,
        &faults,
        request.lsb,
        request.threads,
        progress,
    )?;
    Ok(summary::summarise(summary::Inputs {
        request,
        entries: entries.len(),
        skipped,
        single_unit,
        repairs,
        prepared: &prepared,
        table: &table,
        settings: &settings,
        faults: &faults,
    }))
}
