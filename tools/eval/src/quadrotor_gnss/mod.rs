//! GNSS-aided navigation on the four-IMU quadrotor flights (`rins eval quadrotor --mode
//! gnss|outage`), with the navigator library in-process.
//!
//! The flights have no GNSS recording of their own besides the RTK reference, so a standard
//! receiver is made from it ([`receiver`]): 5 Hz, σ 1.5 m horizontal, 3 m vertical, 0.1 m/s,
//! seeded per flight. Per flight, each unit alone and the four fused run through the aided
//! navigator, started from the reference at t0 as in the free-inertial mode ([`run`]):
//! - `gnss`: the receiver throughout; roll/pitch, heading and horizontal position against the
//!   reference, and how many fixes the consistency monitor rejected (on clean fixes, each is a
//!   false alarm);
//! - `outage`: the receiver cut for the last [`OUTAGE_S`] of each flight; the horizontal error
//!   at the end of the outage, the fused four beside each unit alone.
//!
//! Chosen from these flights, leave-one-flight-out (each flight is scored with what the other
//! flights chose):
//! - the drift test's setting (`[navigator.gnss] drift_slack` and `drift_threshold`,
//!   [`cross_validation`]), on runs with the nominal antenna;
//! - the antenna's lever arm (`[navigator.gnss] lever_arm_m`) and the lead of the reference's
//!   position over the units' clock, from which the receiver's times are made ([`antenna`]).
//!
//! - each series' mounting and gyro bias at t0, as `--mode ahrs` learns them
//!   ([`held_out_start`]): a first pass starts every run from the airframe's attitude with no
//!   bias known; the second, scored, pass starts each flight's runs with what the first pass of
//!   the other flights learnt, and scores the attitude with that mounting.
//!
//! Everything else is the UAV profile's. Beside the figures, each flight's reference is checked
//! against itself and the units ([`reference_check`]): how far any filter that follows the gyros
//! or the positions must stay from its attitude.

pub mod antenna;
pub mod cross_validation;
pub mod held_out_start;
pub mod live;
pub mod receiver;
pub mod reference_check;
pub mod report;
pub mod results;
pub mod run;
#[cfg(test)]
mod synthetic;
pub mod tilt_choice;

pub use results::{FlightResult, GnssMode, GnssReport, RunScores};

use std::path::Path;

use anyhow::{Context, Result, anyhow};
use rins_navigator::inertial_core::AidedConfig;

use crate::datasets::quadrotor::projection::estimate_installation;
use crate::datasets::quadrotor::{
    SkippedTrial, Trial, TruthRow, list_trials, load_trial, nothing_evaluated,
};
use crate::quadrotor_ahrs::SETTLE_S;
use crate::quadrotor_ahrs::mounting::{Paired, fit_mounting, roll_pitch_rmse_deg};
use crate::quadrotor_ahrs::windows;
use crate::quadrotor_nav::frames::{self, Motion};
use crate::quadrotor_nav::metrics::{angle_error, median, rms};
use crate::quadrotor_nav::run::{Start, start_from_truth};
use crate::quadrotor_nav::{require_data_dir, vehicle_from_reference};
use held_out_start::FlightStarts;
use rins_navigator::attitude::quaternion_from_euler;
use run::{GnssTrace, navigate_with_gnss};

/// Length of the outage at the end of each flight, s.
pub const OUTAGE_S: f64 = 10.0;
/// The shortest flight the outage mode scores: the receiver needs some time before the cut.
pub const MIN_OUTAGE_FLIGHT_S: f64 = 15.0;
/// Roll/pitch RMSE the GNSS-aided fused solution is held to, degrees.
pub const ROLL_PITCH_TARGET_DEG: f64 = 0.5;
/// The fused outage error is held to this share of the median single unit's.
pub const OUTAGE_RATIO_TARGET: f64 = 0.7;

/// Scores `trace` against the reference rows `truth` from `start` on.
pub fn score(
    imu: Option<usize>,
    trace: &GnssTrace,
    truth: &[TruthRow],
    start: &Start,
) -> RunScores {
    let (mut rp, mut yaw, mut horiz) = (Vec::new(), Vec::new(), Vec::new());
    let mut paired = Paired::default();
    let mut end = f64::NAN;
    for row in truth.iter().skip(start.row) {
        let i = trace.samples.partition_point(|s| s.t_s < row.t_s);
        let Some(s) = trace
            .samples
            .get(i)
            .filter(|s| (s.t_s - row.t_s).abs() < 0.02)
        else {
            continue;
        };
        let [r, p, y] = s.euler_rad;
        paired.push(
            row.t_s - start.t_s,
            quaternion_from_euler(r, p, y),
            row.roll_rad,
            row.pitch_rad,
        );
        rp.push(angle_error(r, row.roll_rad).to_degrees());
        rp.push(angle_error(p, row.pitch_rad).to_degrees());
        yaw.push(angle_error(y, row.heading_rad).to_degrees());
        let e = (s.north_east_m[0] - row.north_m).hypot(s.north_east_m[1] - row.east_m);
        horiz.push(e);
        end = e;
    }
    RunScores {
        imu,
        roll_pitch_rmse_deg: rms(&rp),
        heading_rmse_deg: rms(&yaw),
        horizontal_rmse_m: rms(&horiz),
        end_horizontal_error_m: end,
        fixes_applied: trace.applied,
        fixes_outliers: trace.outliers,
        rejections: trace.rejections,
        paired,
        final_gyro_bias_rps: trace.final_gyro_bias_rps,
    }
}

/// The figures of one flight; `progress()` after each run.
pub fn evaluate_trial(
    trial: &Trial,
    config: &AidedConfig,
    mode: GnssMode,
    drift_setting: cross_validation::Choice,
    antenna: antenna::Antenna,
    starts: &FlightStarts,
    progress: &mut dyn FnMut(),
) -> Result<FlightResult> {
    let mut config = *config;
    config.gnss.drift_slack = drift_setting.drift_slack;
    config.gnss.drift_threshold = drift_setting.drift_threshold;
    config.gnss.lever_arm_m = antenna.lever_arm_m;
    let config = &config;
    let installation = estimate_installation(trial)?;
    let vehicle = vehicle_from_reference();
    let fused_motion = frames::fused(trial, &installation, &vehicle)?;
    let start = start_from_truth(&trial.truth, fused_motion.t0_s, fused_motion.end_s())
        .ok_or_else(|| anyhow!("{}: no reference row inside the IMU recording", trial.name))?;
    let end_s = trial
        .truth
        .iter()
        .map(|r| r.t_s)
        .rfind(|&t| t <= fused_motion.end_s())
        .unwrap_or(start.t_s);
    let duration_s = end_s - start.t_s;
    if mode == GnssMode::Outage && duration_s < MIN_OUTAGE_FLIGHT_S {
        return Err(anyhow!(
            "{}: {duration_s:.1} s of flight, shorter than the {MIN_OUTAGE_FLIGHT_S} s an outage of {OUTAGE_S} s needs",
            trial.name
        ));
    }
    let fixes = receiver::epochs(
        &trial.truth,
        start.t_s,
        end_s,
        antenna.position_lead_s,
        receiver::seed_of(&trial.name),
    );
    let gnss_until_s = match mode {
        GnssMode::Gnss => f64::INFINITY,
        GnssMode::Outage => end_s - OUTAGE_S,
    };
    let mut run = |imu: Option<usize>, motion: &Motion| {
        let known = starts.of(imu).known;
        let trace = navigate_with_gnss(motion, &start, &known, config, &fixes, gnss_until_s);
        progress();
        (score(imu, &trace, &trial.truth, &start), trace)
    };
    let mut single = Vec::with_capacity(trial.imus.len());
    for (index, series) in trial.imus.iter().enumerate() {
        let motion = frames::single(trial, &installation, &vehicle, index)?;
        single.push(run(Some(series.imu), &motion).0);
    }
    let (fused, trace) = run(None, &fused_motion);
    let scored = live::ScoredGnssRun {
        flight: trial.name.clone(),
        motion: fused_motion,
        start,
        known: starts.fused.known,
        config: *config,
        fixes,
        gnss_until_s,
        tilt_rad: starts.fused.tilt_rad,
        truth: trial.truth.clone(),
        trace,
    };
    let fused_roll_pitch_rmse_mounted_deg =
        roll_pitch_rmse_deg(&fused.paired, starts.fused.tilt_rad, 0.0);
    let fused_window_rmse_deg = windows::of(&fused.paired, starts.fused.tilt_rad);
    let median_single_end_error_m = median(
        &single
            .iter()
            .map(|s| s.end_horizontal_error_m)
            .collect::<Vec<_>>(),
    );
    Ok(FlightResult {
        name: trial.name.clone(),
        duration_s,
        single,
        fused,
        median_single_end_error_m,
        drift_setting,
        tilt_setting: String::new(),
        antenna,
        fused_roll_pitch_rmse_mounted_deg,
        fused_window_rmse_deg,
        scored: Some(Box::new(scored)),
        live: None,
        reference_check: Default::default(),
        // Filled in once every flight has run: the mounting is fitted on all.
        fused_roll_pitch_rmse_mounted_in_sample_deg: f64::NAN,
    })
}

/// Scores each flight's fused attitude with the units' mounting tilt fitted on every flight, this
/// one included (in sample).
fn score_mounted_in_sample(trials: &mut [FlightResult]) {
    let all: Vec<&Paired> = trials.iter().map(|t| &t.fused.paired).collect();
    let in_sample = fit_mounting(&all, SETTLE_S);
    for t in trials.iter_mut() {
        t.fused_roll_pitch_rmse_mounted_in_sample_deg =
            roll_pitch_rmse_deg(&t.fused.paired, in_sample, 0.0);
    }
}

/// [`evaluate`], and each flight's scored fused run (in the report's flight order), for the
/// running service to repeat.
pub fn evaluate_with_runs(
    dir: &Path,
    config: &AidedConfig,
    mode: GnssMode,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<(GnssReport, Vec<live::ScoredGnssRun>)> {
    let mut report = evaluate(dir, config, mode, progress)?;
    let runs = report
        .trials
        .iter_mut()
        .filter_map(|t| t.scored.take().map(|r| *r))
        .collect();
    Ok((report, runs))
}

/// Every flight under `dir`; `progress(done, total)` after each navigator run.
pub fn evaluate(
    dir: &Path,
    config: &AidedConfig,
    mode: GnssMode,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<GnssReport> {
    require_data_dir(dir)?;
    let entries = list_trials(dir)
        .with_context(|| format!("eval quadrotor: cannot list trials in {}", dir.display()))?;
    let n = cross_validation::CANDIDATES.len();
    let passes = n + tilt_choice::settings(&config.tilt).len() + 1;
    let total: usize = entries.iter().map(|e| (e.imus.len() + 1) * passes).sum();
    let mut done = 0;
    let mut loaded = Vec::new();
    let mut skipped = Vec::new();
    for entry in &entries {
        let trial = load_trial(&entry.path)
            .map_err(anyhow::Error::from)
            .and_then(|trial| {
                // A single unit is no comparison of fused against single in an outage.
                if mode == GnssMode::Outage && trial.imus.len() < 2 {
                    return Err(anyhow!("{}: one unit only, nothing to fuse", trial.name));
                }
                Ok(trial)
            });
        match trial {
            Ok(t) => loaded.push(t),
            Err(e) => skipped.push(SkippedTrial {
                trial: entry.name.clone(),
                reason: format!("{e:#}"),
            }),
        }
    }
    // Every flight under every drift setting, for the cross-validation.
    let mut rejections = Vec::with_capacity(loaded.len());
    let mut usable = Vec::with_capacity(loaded.len());
    for trial in &loaded {
        let mut per = Vec::with_capacity(n);
        let mut failed = None;
        for (c, &(drift_slack, drift_threshold)) in cross_validation::CANDIDATES.iter().enumerate()
        {
            let choice = cross_validation::Choice {
                candidate: c,
                drift_slack,
                drift_threshold,
            };
            // The nominal antenna: the drift setting is chosen without the antenna fit.
            let (nominal_antenna, nominal_start) = Default::default();
            match evaluate_trial(
                trial,
                config,
                mode,
                choice,
                nominal_antenna,
                &nominal_start,
                &mut || {
                    done += 1;
                    progress(done, total);
                },
            ) {
                Ok(r) => per.push(
                    r.single
                        .iter()
                        .chain(std::iter::once(&r.fused))
                        .map(|s| s.rejections)
                        .sum(),
                ),
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        match failed {
            Some(e) => skipped.push(SkippedTrial {
                trial: trial.name.clone(),
                reason: format!("{e:#}"),
            }),
            None => {
                rejections.push(per);
                usable.push(trial);
            }
        }
    }
    let chosen = cross_validation::choose(&rejections);
    let equations: Vec<antenna::NormalEquations> =
        usable.iter().map(|t| antenna_equations(t)).collect();
    let antennas = antenna::held_out(&equations);
    let antenna_in_sample = antenna::in_sample(&equations);
    // First pass, under each tilt setting: every run from the airframe's attitude, no bias known.
    let settings = tilt_choice::settings(&config.tilt);
    let with_tilt = |setting: &tilt_choice::TiltSetting| {
        let mut c = *config;
        c.tilt = setting.tilt;
        c
    };
    let mut first: Vec<Vec<FlightResult>> = vec![Vec::with_capacity(usable.len()); settings.len()];
    let mut kept = Vec::with_capacity(usable.len());
    'flights: for ((trial, choice), antenna) in usable.into_iter().zip(chosen).zip(antennas) {
        let mut runs = Vec::with_capacity(settings.len());
        for setting in &settings {
            let result = evaluate_trial(
                trial,
                &with_tilt(setting),
                mode,
                choice,
                antenna,
                &FlightStarts::default(),
                &mut || {
                    done += 1;
                    progress(done, total);
                },
            );
            match result {
                Ok(r) => runs.push(r),
                Err(e) => {
                    skipped.push(SkippedTrial {
                        trial: trial.name.clone(),
                        reason: format!("{e:#}"),
                    });
                    continue 'flights;
                }
            }
        }
        for (s, r) in runs.into_iter().enumerate() {
            first[s].push(r);
        }
        kept.push((trial, choice, antenna));
    }
    // Second pass, scored: each flight with the tilt setting the others' first pass preferred,
    // started with what the others' first pass under it learnt.
    let tilt_choice = tilt_choice::choose(&first);
    let starts: Vec<Vec<FlightStarts>> = first
        .iter()
        .map(|f| held_out_start::held_out_starts(f))
        .collect();
    let mut trials = Vec::with_capacity(kept.len());
    for (f, (trial, choice, antenna)) in kept.into_iter().enumerate() {
        let s = tilt_choice[f];
        let config = with_tilt(&settings[s]);
        let result = evaluate_trial(
            trial,
            &config,
            mode,
            choice,
            antenna,
            &starts[s][f],
            &mut || {
                done += 1;
                progress(done, total);
            },
        );
        match result {
            Ok(r) => trials.push(FlightResult {
                tilt_setting: settings[s].name.to_string(),
                ..r
            }),
            Err(e) => skipped.push(SkippedTrial {
                trial: trial.name.clone(),
                reason: format!("{e:#}"),
            }),
        }
    }
    progress(total, total);
    if trials.is_empty() {
        return Err(anyhow!("eval quadrotor: {}", nothing_evaluated(&skipped)));
    }
    score_mounted_in_sample(&mut trials);
    for t in &mut trials {
        if let Some(run) = &t.scored {
            t.reference_check =
                reference_check::check(&run.truth, &run.motion, run.tilt_rad, &t.antenna);
        }
    }
    let mut report = results::summarise(dir, mode, trials, skipped);
    report.antenna_in_sample = antenna_in_sample;
    Ok(report)
}

/// One flight's share of the antenna fit: its reference against its fused units' motion (none
/// when the units cannot be fused, which the flight's own run reports).
fn antenna_equations(trial: &Trial) -> antenna::NormalEquations {
    estimate_installation(trial)
        .ok()
        .and_then(|installation| {
            frames::fused(trial, &installation, &vehicle_from_reference()).ok()
        })
        .map(|motion| antenna::normal_equations(&trial.truth, &motion))
        .unwrap_or_default()
}
