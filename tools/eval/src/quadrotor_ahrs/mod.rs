//! Attitude without position aiding on the four-IMU quadrotor recordings (`rins eval quadrotor
//! --mode ahrs`): the navigator's tilt updates (AHRS) against the airframe's reference attitude,
//! beside each unit alone and each unit's own on-board filter (the peer), every figure
//! cross-validated leave-one-flight-out.
//!
//! Per flight: each unit's rate and specific force in the reference unit's axes, the four fused
//! ([`crate::quadrotor_nav::frames`]); the filter starts from the reference at t0 (attitude, height,
//! velocity with σ 5 m/s: the drag model's velocity is the airspeed, which differs from the
//! ground speed by the wind) with an unknown gyro bias (σ 0.5 °/s: the units ran long before the
//! recording starts), and is never told the reference again ([`run`]).
//!
//! Cross-validation ([`cross_validation`]), for each flight F in turn:
//! 1. every candidate setting of `[navigator.tilt]` ([`candidates`]) has run every flight, started
//!    from the airframe's attitude; on the flights other than F, the fused solution's mounting tilt
//!    is fitted (rows after the first [`SETTLE_S`]) and the candidate scored;
//! 2. the candidate with the lowest mean roll/pitch RMSE on the other flights runs F again, now
//!    started from the airframe's attitude turned by that mounting (the unit's attitude), and F is
//!    scored with that mounting;
//! 3. each unit alone (same candidate) and each unit's on-board filter are scored the same way,
//!    each with its own mounting fitted on the other flights that have the unit.
//!
//! Nothing learnt from F is used to score F. A flight that cannot be loaded or prepared is
//! reported with its reason and left out; the evaluation goes on.
//!
//! Beside rins, scored the same way: Madgwick's and Mahony's filters on the same motion
//! ([`reference_cv`]), the average of the units' own filters ([`peer_average`]), and every
//! series over windows of time since the start ([`windows`]).

pub mod candidates;
pub mod cross_validation;
pub mod honesty;
pub mod live;
pub mod mounting;
pub mod peer_average;
pub mod reference_algorithms;
pub mod reference_cv;
pub mod reference_filter;
pub mod reference_report;
pub mod report;
pub mod run;
pub mod windows;

use std::path::{Path, PathBuf};

use anyhow::{Result, anyhow};
use nalgebra::UnitQuaternion;
use rins_navigator::attitude::quaternion_from_euler;
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use crate::datasets::quadrotor::projection::estimate_installation;
use crate::datasets::quadrotor::{
    MAX_IMUS, Repairs, SkippedTrial, Trial, load_each, nothing_evaluated, total_repairs,
};
use crate::quadrotor_nav::frames::{self, Motion};
use crate::quadrotor_nav::run::{Start, start_from_truth};
use crate::quadrotor_nav::{require_data_dir, vehicle_from_reference};
use candidates::Candidate;
use live::ScoredRun;
use mounting::Paired;
use reference_cv::{PeerAverageScore, ReferenceFlight};
use reference_report::ReferenceSummary;
use run::AttitudeTrace;
use windows::WindowRmse;

/// Initial velocity σ of every run, m/s (see the module docs).
pub const INITIAL_VELOCITY_SIGMA_MPS: f64 = 5.0;
/// Initial gyro bias σ of every run, °/s (see the module docs).
pub const INITIAL_GYRO_BIAS_SIGMA_DPS: f64 = 0.5;
/// Rows of the first seconds of a run are left out of mounting fits and of the choice of the
/// candidate: a run started from the airframe's attitude needs them to find the unit's, s.
pub const SETTLE_S: f64 = 5.0;
/// The fused roll/pitch RMSE the mode is held to on these flights, degrees.
pub const ROLL_PITCH_TARGET_DEG: f64 = 0.5;

/// A flight ready to run.
pub(crate) struct Flight {
    name: String,
    imus: Vec<usize>,
    fused: Motion,
    singles: Vec<Motion>,
    start: Start,
    /// Reference rows after t0: time, roll, pitch.
    rows: Vec<(f64, f64, f64)>,
    /// Each unit's on-board attitude paired with the reference rows.
    peers: Vec<Paired>,
    /// The average of the units' on-board attitudes paired with the reference rows.
    peer_average: Paired,
    truth_offset_s: f64,
    file_offsets_s: Vec<f64>,
    repairs: Repairs,
    notes: Vec<String>,
}

/// One flight's cross-validated figures.
#[derive(Debug, Clone, Serialize)]
pub struct FlightResult {
    /// `<group>/path_<N>`.
    pub name: String,
    /// IMU file numbers present.
    pub imus: Vec<usize>,
    /// Reference rows scored.
    pub rows: usize,
    /// The candidate chosen on the other flights.
    pub candidate: String,
    /// Fused units (a single unit when only one is present), roll/pitch RMSE, degrees.
    pub fused_roll_pitch_rmse_deg: f64,
    /// Each unit alone through rins, by unit number 1..=4 (null when absent).
    pub single_roll_pitch_rmse_deg: [Option<f64>; MAX_IMUS],
    /// Each unit's own on-board filter, by unit number (null when absent).
    pub peer_roll_pitch_rmse_deg: [Option<f64>; MAX_IMUS],
    /// Added to the reference's file times to put them on the reference unit's clock (estimated
    /// from the gyro against the reference's body rates), s.
    pub truth_offset_s: f64,
    /// Each present unit file's own offset to the reference's clock, s.
    pub file_offsets_s: Vec<f64>,
    /// What the loader repaired in this flight's files.
    pub repairs: Repairs,
    /// What the loader repaired or noticed.
    pub notes: Vec<String>,
    /// The fused RMSE over the windows of time since the start
    /// ([`windows::WINDOW_STARTS_S`]), degrees.
    pub fused_window_rmse_deg: WindowRmse,
    /// The fused run's tilt error over its own σ, RMS over the first seconds and the rest
    /// ([`honesty::WINDOWS_S`]): 1 where the σ is right.
    pub fused_error_over_sigma: honesty::ErrorOverSigma,
    /// Each unit's own filter over the same windows, by unit number (null when absent).
    pub peer_window_rmse_deg: [Option<WindowRmse>; MAX_IMUS],
    /// The normalised average of the units' own filters, scored the same way.
    pub peer_average: PeerAverageScore,
    /// Madgwick's filter on the same motion.
    pub madgwick: ReferenceFlight,
    /// Mahony's filter on the same motion.
    pub mahony: ReferenceFlight,
    /// The same run through the running processes (`--live`).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub live: Option<live::LiveFlight>,
}

/// One candidate's in-sample figure (first pass, gyro bias learnt from zero, every flight after
/// [`SETTLE_S`], mounting fitted on all of them): shown for transparency, not used to choose.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateFigure {
    /// The candidate.
    pub name: String,
    /// Mean fused roll/pitch RMSE over the flights, degrees.
    pub in_sample_roll_pitch_rmse_deg: f64,
    /// Flights on which the cross-validation chose it.
    pub chosen: usize,
}

/// The whole data set.
#[derive(Debug, Clone, Serialize)]
pub struct AhrsReport {
    /// Data set directory.
    pub dir: PathBuf,
    /// Flights listed.
    pub flights_total: usize,
    /// Flights evaluated.
    pub flights_evaluated: usize,
    /// Flights left out, with reasons.
    pub failures: Vec<SkippedTrial>,
    /// What the loader repaired, by kind, over every flight (failed flights counted).
    pub repairs: Repairs,
    /// Mean over flights of the fused roll/pitch RMSE, degrees (cross-validated).
    pub roll_pitch_rmse_deg: f64,
    /// Per unit (1..=4): mean over the flights that have it of its roll/pitch RMSE through rins.
    pub single_roll_pitch_rmse_deg: [Option<f64>; MAX_IMUS],
    /// Per unit: mean of its on-board filter's roll/pitch RMSE, scored the same way.
    pub peer_roll_pitch_rmse_deg: [Option<f64>; MAX_IMUS],
    /// The fused mean is below every unit's on-board filter's.
    pub fused_better_than_every_peer: bool,
    /// The fused mean is below every unit's alone.
    pub fused_better_than_every_single: bool,
    /// Target for the fused mean, degrees ([`ROLL_PITCH_TARGET_DEG`]).
    pub roll_pitch_target_deg: f64,
    /// The fused mean meets the target.
    pub roll_pitch_target_met: bool,
    /// Every candidate's in-sample figure and how often it was chosen.
    pub candidates: Vec<CandidateFigure>,
    /// Mean over flights of [`FlightResult::fused_error_over_sigma`].
    pub fused_error_over_sigma: honesty::ErrorOverSigma,
    /// The reference filters and the average of the units' own filters, scored the same way,
    /// and the windows of time since the start.
    #[serde(flatten)]
    pub references: ReferenceSummary,
    /// Per flight.
    pub flights: Vec<FlightResult>,
    /// The fused runs through the running processes (`--live`).
    #[serde(flatten, skip_serializing_if = "Option::is_none")]
    pub live: Option<live::LiveSummary>,
}

/// The reference's attitude pairs for `trace` at the flight's rows.
pub(crate) fn pair(trace: &AttitudeTrace, start_s: f64, rows: &[(f64, f64, f64)]) -> Paired {
    let mut p = Paired::default();
    for &(t, roll, pitch) in rows {
        if let Some(q) = trace.at(t) {
            p.push(t - start_s, q, roll, pitch);
        }
    }
    p
}

fn prepare(trial: Trial) -> Result<Flight> {
    let installation = estimate_installation(&trial)?;
    let vehicle = vehicle_from_reference();
    let fused = frames::fused(&trial, &installation, &vehicle)?;
    let singles = (0..trial.imus.len())
        .map(|k| frames::single(&trial, &installation, &vehicle, k))
        .collect::<Result<Vec<_>>>()?;
    let start = start_from_truth(&trial.truth, fused.t0_s, fused.end_s()).ok_or_else(|| {
        anyhow!(
            "no reference row inside the IMU recording ({:.2}..{:.2} s) to start from",
            fused.t0_s,
            fused.end_s()
        )
    })?;
    let rows: Vec<(f64, f64, f64)> = trial
        .truth
        .iter()
        .skip(start.row + 1)
        .filter(|r| r.t_s <= fused.end_s())
        .map(|r| (r.t_s, r.roll_rad, r.pitch_rad))
        .collect();
    let traces: Vec<AttitudeTrace> = trial
        .imus
        .iter()
        .map(|series| AttitudeTrace {
            t_s: series.samples.iter().map(|s| s.t_s).collect(),
            attitude: series
                .samples
                .iter()
                .map(|s| quaternion_from_euler(s.euler_rad[0], s.euler_rad[1], s.euler_rad[2]))
                .collect::<Vec<UnitQuaternion<f64>>>(),
            tilt_sigma_rad: Vec::new(),
        })
        .collect();
    let peers = traces
        .iter()
        .map(|trace| pair(trace, start.t_s, &rows))
        .collect();
    let peer_average = peer_average::pair_average(&traces, start.t_s, &rows);
    Ok(Flight {
        name: trial.name.clone(),
        imus: trial.imus.iter().map(|s| s.imu).collect(),
        file_offsets_s: trial.imus.iter().map(|s| s.truth_offset_s).collect(),
        truth_offset_s: trial.truth_offset_s,
        repairs: trial.repairs,
        notes: trial.notes,
        fused,
        singles,
        start,
        rows,
        peers,
        peer_average,
    })
}

/// The profile's settings with the candidate's tilt updates and the eval's start rules.
pub(crate) fn with_candidate(base: &AidedConfig, candidate: &Candidate) -> AidedConfig {
    let mut config = *base;
    config.tilt = candidate.tilt;
    config.baro.enabled = false;
    config.mag.enabled = false;
    config.zupt.enabled = false;
    config.noise.initial_velocity_sigma = INITIAL_VELOCITY_SIGMA_MPS;
    config.noise.initial_gyro_bias_sigma = INITIAL_GYRO_BIAS_SIGMA_DPS.to_radians();
    config
}

/// Every flight under `dir`; `progress(done, total)` as the runs go.
pub fn evaluate(
    dir: &Path,
    base: &AidedConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<AhrsReport> {
    evaluate_with_runs(dir, base, progress).map(|(report, _)| report)
}

/// [`evaluate`], with the fused run that scored each flight (in the report's flight order).
pub fn evaluate_with_runs(
    dir: &Path,
    base: &AidedConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(AhrsReport, Vec<ScoredRun>)> {
    require_data_dir(dir)?;
    let loaded = load_each(dir, |_, _| ()).map_err(|e| {
        anyhow!(
            "eval quadrotor: cannot list trials in {}: {e}",
            dir.display()
        )
    })?;
    if loaded.is_empty() {
        return Err(anyhow!(
            "eval quadrotor: no trials (<group>/path_<N>/IMU_k.csv) in {}",
            dir.display()
        ));
    }
    let mut repairs = total_repairs(&loaded);
    let flights_total = loaded.len();
    let grid = candidates::grid(&base.tilt);
    let total = flights_total * (grid.len() + MAX_IMUS + 2);
    let mut done = 0;
    progress(done, total);
    let mut flights = Vec::new();
    let mut failures = Vec::new();
    for (entry, trial) in loaded {
        let prepared = trial
            .map_err(anyhow::Error::from)
            .and_then(|t| prepare(t).inspect_err(|_| repairs.trials_failed += 1));
        match prepared {
            Ok(f) => flights.push(f),
            Err(e) => failures.push(SkippedTrial {
                trial: entry.name.clone(),
                reason: format!("{e:#}"),
            }),
        }
        done += 1;
        progress(done, total);
    }
    if flights.is_empty() {
        return Err(anyhow!("eval quadrotor: {}", nothing_evaluated(&failures)));
    }
    let outcome = cross_validation::run(&flights, &grid, base, &mut |runs| {
        done += runs;
        progress(done.min(total), total);
    });
    let references = reference_cv::score_all(&flights, outcome.flights);
    progress(total, total);
    let mut report = report::summarise(
        dir,
        flights_total,
        repairs,
        failures,
        references.flights,
        outcome.candidates,
    );
    report.references = reference_report::summarise(&report.flights, references.grids);
    Ok((report, outcome.runs))
}
