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
//! One setting is chosen from these flights, the drift test's (`[navigator.gnss] drift_slack`
//! and `drift_threshold`), leave-one-flight-out ([`cross_validation`]): each flight is scored
//! with the setting the other flights chose. Everything else is the UAV profile's.

pub mod cross_validation;
pub mod receiver;
pub mod report;
pub mod run;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use crate::datasets::quadrotor::projection::estimate_installation;
use crate::datasets::quadrotor::{SkippedTrial, Trial, list_trials, load_trial, nothing_evaluated};
use crate::quadrotor_ahrs::SETTLE_S;
use crate::quadrotor_ahrs::mounting::{Paired, fit_mounting, roll_pitch_rmse_deg};
use crate::quadrotor_nav::frames::{self, Motion};
use crate::quadrotor_nav::metrics::{angle_error, mean, median, rms};
use crate::quadrotor_nav::run::{Start, start_from_truth};
use crate::quadrotor_nav::{require_data_dir, vehicle_from_reference};
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

/// What the receiver does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GnssMode {
    /// Fixes throughout.
    Gnss,
    /// Fixes cut for the last [`OUTAGE_S`].
    Outage,
}

/// One run's figures.
#[derive(Debug, Clone, Serialize)]
pub struct RunScores {
    /// IMU file number; absent for the fused units.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imu: Option<usize>,
    /// RMS of roll and pitch errors together, degrees.
    pub roll_pitch_rmse_deg: f64,
    /// RMS of the heading error, degrees.
    pub heading_rmse_deg: f64,
    /// RMS of the horizontal position error, m.
    pub horizontal_rmse_m: f64,
    /// Horizontal error at the last reference row of the run (the end of the outage), m.
    pub end_horizontal_error_m: f64,
    /// Fixes applied, outliers, skipped while rejected; times the receiver was rejected.
    pub fixes_applied: usize,
    /// Fixes outside the gate.
    pub fixes_outliers: usize,
    /// Times the monitor rejected the receiver.
    pub rejections: u64,
    /// The solution's attitude at each scored reference row, for the mounting fit.
    #[serde(skip)]
    pub paired: Paired,
}

/// One flight's figures.
#[derive(Debug, Clone, Serialize)]
pub struct FlightResult {
    /// `<group>/path_<N>`.
    pub name: String,
    /// From t0 to the last reference row scored, s.
    pub duration_s: f64,
    /// Each unit alone, in file order.
    pub single: Vec<RunScores>,
    /// The units fused.
    pub fused: RunScores,
    /// Median over the single units of the end horizontal error, m.
    pub median_single_end_error_m: f64,
    /// The drift test's setting, chosen on the other flights.
    pub drift_setting: cross_validation::Choice,
    /// The fused roll/pitch RMSE with the units' mounting tilt fitted on the other flights, as
    /// `--mode ahrs` scores, degrees (the mounting is the airframe's, not the flight's).
    pub fused_roll_pitch_rmse_mounted_deg: f64,
    /// The same with the mounting fitted on every flight, this one included: in sample, shown
    /// beside the held-out figure so that overfitting shows.
    pub fused_roll_pitch_rmse_mounted_in_sample_deg: f64,
}

/// The whole data set's figures.
#[derive(Debug, Clone, Serialize)]
pub struct GnssReport {
    /// The data set directory.
    pub dir: PathBuf,
    /// `gnss` or `outage`.
    pub mode: GnssMode,
    /// Every flight's figures.
    pub trials: Vec<FlightResult>,
    /// Mean over flights of the fused roll/pitch RMSE, degrees.
    pub roll_pitch_rmse_deg: f64,
    /// Mean over flights of the fused roll/pitch RMSE with the mounting fitted on the other
    /// flights ([`FlightResult::fused_roll_pitch_rmse_mounted_deg`]), degrees.
    pub roll_pitch_rmse_mounted_deg: f64,
    /// The same with the mounting fitted on every flight (in sample), degrees.
    pub roll_pitch_rmse_mounted_in_sample_deg: f64,
    /// The fused roll/pitch RMSE is within [`ROLL_PITCH_TARGET_DEG`] (`gnss` mode).
    pub roll_pitch_target_met: bool,
    /// Mean over flights of the fused heading RMSE, degrees.
    pub heading_rmse_deg: f64,
    /// Mean over flights of the fused horizontal RMSE, m.
    pub horizontal_rmse_m: f64,
    /// Receiver rejections over every run (fused and single), each flight with the drift
    /// setting chosen on the others: false alarms on these clean fixes.
    pub gnss_rejections: u64,
    /// The same over the fused runs only.
    pub gnss_rejections_fused: u64,
    /// Outage mode: mean over flights of the fused end-of-outage horizontal error, m.
    pub outage_error_m: f64,
    /// Outage mode: mean over flights of each unit's (by file number) end-of-outage error, m.
    pub single_outage_error_m: Vec<f64>,
    /// Outage mode: mean over flights of the median single unit's error, m.
    pub median_single_outage_error_m: f64,
    /// `outage_error_m / median_single_outage_error_m`.
    pub outage_ratio: f64,
    /// The ratio is within [`OUTAGE_RATIO_TARGET`] (`outage` mode).
    pub outage_target_met: bool,
    /// Flights listed but not evaluated, with the reason.
    pub skipped: Vec<SkippedTrial>,
}

/// Scores `trace` against the reference rows from `start` on.
fn score(imu: Option<usize>, trace: &GnssTrace, trial: &Trial, start: &Start) -> RunScores {
    let (mut rp, mut yaw, mut horiz) = (Vec::new(), Vec::new(), Vec::new());
    let mut paired = Paired::default();
    let mut end = f64::NAN;
    for row in trial.truth.iter().skip(start.row) {
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
    }
}

/// The figures of one flight; `progress()` after each run.
pub fn evaluate_trial(
    trial: &Trial,
    config: &AidedConfig,
    mode: GnssMode,
    drift_setting: cross_validation::Choice,
    progress: &mut dyn FnMut(),
) -> Result<FlightResult> {
    let mut config = *config;
    config.gnss.drift_slack = drift_setting.drift_slack;
    config.gnss.drift_threshold = drift_setting.drift_threshold;
    let config = &config;
    let installation = estimate_installation(trial)?;
    let vehicle = vehicle_from_reference();
    let fused = frames::fused(trial, &installation, &vehicle)?;
    let start = start_from_truth(&trial.truth, fused.t0_s, fused.end_s())
        .ok_or_else(|| anyhow!("{}: no reference row inside the IMU recording", trial.name))?;
    let end_s = trial
        .truth
        .iter()
        .map(|r| r.t_s)
        .rfind(|&t| t <= fused.end_s())
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
        receiver::seed_of(&trial.name),
    );
    let gnss_until_s = match mode {
        GnssMode::Gnss => f64::INFINITY,
        GnssMode::Outage => end_s - OUTAGE_S,
    };
    let mut run = |imu: Option<usize>, motion: &Motion| {
        let trace = navigate_with_gnss(motion, &start, config, &fixes, gnss_until_s);
        progress();
        score(imu, &trace, trial, &start)
    };
    let mut single = Vec::with_capacity(trial.imus.len());
    for (index, series) in trial.imus.iter().enumerate() {
        let motion = frames::single(trial, &installation, &vehicle, index)?;
        single.push(run(Some(series.imu), &motion));
    }
    let fused = run(None, &fused);
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
        // Filled in once every flight has run: the mounting is fitted on the others.
        fused_roll_pitch_rmse_mounted_deg: f64::NAN,
        fused_roll_pitch_rmse_mounted_in_sample_deg: f64::NAN,
    })
}

/// Scores each flight's fused attitude with the units' mounting tilt fitted on the other
/// flights (the rows after [`SETTLE_S`]), and on all of them for the in-sample figure.
fn score_mounted(trials: &mut [FlightResult]) {
    let all: Vec<&Paired> = trials.iter().map(|t| &t.fused.paired).collect();
    let in_sample = fit_mounting(&all, SETTLE_S);
    let held_out: Vec<[f64; 2]> = (0..trials.len())
        .map(|f| {
            let others: Vec<&Paired> = all
                .iter()
                .enumerate()
                .filter(|&(g, _)| g != f)
                .map(|(_, p)| *p)
                .collect();
            fit_mounting(&others, SETTLE_S)
        })
        .collect();
    for (t, tilt) in trials.iter_mut().zip(held_out) {
        t.fused_roll_pitch_rmse_mounted_deg = roll_pitch_rmse_deg(&t.fused.paired, tilt, 0.0);
        t.fused_roll_pitch_rmse_mounted_in_sample_deg =
            roll_pitch_rmse_deg(&t.fused.paired, in_sample, 0.0);
    }
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
    let total: usize = entries.iter().map(|e| (e.imus.len() + 1) * (n + 1)).sum();
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
            match evaluate_trial(trial, config, mode, choice, &mut || {
                done += 1;
                progress(done, total);
            }) {
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
    let mut trials = Vec::with_capacity(usable.len());
    for (trial, choice) in usable.into_iter().zip(chosen) {
        let result = evaluate_trial(trial, config, mode, choice, &mut || {
            done += 1;
            progress(done, total);
        });
        match result {
            Ok(r) => trials.push(r),
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
    score_mounted(&mut trials);
    Ok(summarise(dir, mode, trials, skipped))
}

fn summarise(
    dir: &Path,
    mode: GnssMode,
    trials: Vec<FlightResult>,
    skipped: Vec<SkippedTrial>,
) -> GnssReport {
    let of = |f: &dyn Fn(&FlightResult) -> f64| mean(&trials.iter().map(f).collect::<Vec<_>>());
    let units = trials.iter().map(|t| t.single.len()).max().unwrap_or(0);
    let single_outage_error_m = (0..units)
        .map(|k| {
            mean(
                &trials
                    .iter()
                    .filter_map(|t| t.single.get(k).map(|s| s.end_horizontal_error_m))
                    .collect::<Vec<_>>(),
            )
        })
        .collect();
    let roll_pitch = of(&|t| t.fused.roll_pitch_rmse_deg);
    let outage = of(&|t| t.fused.end_horizontal_error_m);
    let median_single = of(&|t| t.median_single_end_error_m);
    let ratio = outage / median_single;
    GnssReport {
        dir: dir.to_path_buf(),
        mode,
        roll_pitch_rmse_deg: roll_pitch,
        roll_pitch_rmse_mounted_deg: of(&|t| t.fused_roll_pitch_rmse_mounted_deg),
        roll_pitch_rmse_mounted_in_sample_deg: of(&|t| {
            t.fused_roll_pitch_rmse_mounted_in_sample_deg
        }),
        roll_pitch_target_met: roll_pitch <= ROLL_PITCH_TARGET_DEG,
        heading_rmse_deg: of(&|t| t.fused.heading_rmse_deg),
        horizontal_rmse_m: of(&|t| t.fused.horizontal_rmse_m),
        gnss_rejections: trials
            .iter()
            .flat_map(|t| t.single.iter().chain(std::iter::once(&t.fused)))
            .map(|r| r.rejections)
            .sum(),
        gnss_rejections_fused: trials.iter().map(|t| t.fused.rejections).sum(),
        outage_error_m: outage,
        single_outage_error_m,
        median_single_outage_error_m: median_single,
        outage_ratio: ratio,
        outage_target_met: mode == GnssMode::Outage && ratio <= OUTAGE_RATIO_TARGET,
        trials,
        skipped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor_ahrs::mounting::mounting_rotation;

    /// A flight whose solution is the reference turned by the mounting `tilt`, at 1 Hz.
    fn flight(tilt: [f64; 2], roll_deg: f64) -> FlightResult {
        let mut paired = Paired::default();
        let m_inv = mounting_rotation(tilt).inverse();
        for k in 0..60 {
            let (roll, pitch, yaw) = (roll_deg.to_radians(), (k as f64 * 0.01).sin(), 0.3);
            let vehicle = quaternion_from_euler(roll, pitch, yaw);
            paired.push(k as f64, vehicle * m_inv, roll, pitch);
        }
        let run = RunScores {
            imu: None,
            roll_pitch_rmse_deg: f64::NAN,
            heading_rmse_deg: f64::NAN,
            horizontal_rmse_m: f64::NAN,
            end_horizontal_error_m: f64::NAN,
            fixes_applied: 0,
            fixes_outliers: 0,
            rejections: 0,
            paired,
        };
        FlightResult {
            name: String::new(),
            duration_s: 60.0,
            single: Vec::new(),
            fused: run,
            median_single_end_error_m: f64::NAN,
            drift_setting: cross_validation::Choice {
                candidate: 0,
                drift_slack: 0.0,
                drift_threshold: 0.0,
            },
            fused_roll_pitch_rmse_mounted_deg: f64::NAN,
            fused_roll_pitch_rmse_mounted_in_sample_deg: f64::NAN,
        }
    }

    #[test]
    fn each_flight_is_scored_with_the_mounting_of_the_others() {
        let tilt = [0.7_f64.to_radians(), -0.5_f64.to_radians()];
        let mut same = vec![flight(tilt, 2.0), flight(tilt, -3.0), flight(tilt, 5.0)];
        score_mounted(&mut same);
        for t in &same {
            // The airframe's mounting, learnt from the other flights, removes the whole error.
            assert!(
                t.fused_roll_pitch_rmse_mounted_deg < 1e-6,
                "{}",
                t.fused_roll_pitch_rmse_mounted_deg
            );
            assert!(t.fused_roll_pitch_rmse_mounted_in_sample_deg < 1e-6);
        }
        // A flight mounted otherwise than the two others keeps the difference held out, and shares
        // it in sample.
        let mut odd = vec![
            flight(tilt, 2.0),
            flight(tilt, -3.0),
            flight([0.0, 0.0], 5.0),
        ];
        score_mounted(&mut odd);
        let held_out = odd[2].fused_roll_pitch_rmse_mounted_deg;
        let rms_tilt_deg = ((tilt[0].powi(2) + tilt[1].powi(2)) / 2.0)
            .sqrt()
            .to_degrees();
        assert!(
            (held_out - rms_tilt_deg).abs() < 0.02,
            "{held_out} vs {rms_tilt_deg}"
        );
        assert!(odd[2].fused_roll_pitch_rmse_mounted_in_sample_deg < held_out);
    }
}
