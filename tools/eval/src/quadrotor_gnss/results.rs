//! What the GNSS modes report: per run, per flight and over the data set.

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::reference_check::ReferenceCheck;
use super::{OUTAGE_RATIO_TARGET, ROLL_PITCH_TARGET_DEG, antenna, cross_validation, live};
use crate::datasets::quadrotor::SkippedTrial;
use crate::quadrotor_ahrs::live::{LiveFlight, LiveSummary};
use crate::quadrotor_ahrs::mounting::Paired;
use crate::quadrotor_ahrs::windows::{self, WindowRmse};
use crate::quadrotor_nav::metrics::mean;

/// What the receiver does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GnssMode {
    /// Fixes throughout.
    Gnss,
    /// Fixes cut for the last [`super::OUTAGE_S`].
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
    /// The filter's gyro bias at the end, body FRD, rad/s, for the next flights' prior.
    #[serde(skip)]
    pub final_gyro_bias_rps: [f64; 3],
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
    /// The tilt updates' setting, chosen on the other flights ([`super::tilt_choice`]).
    pub tilt_setting: String,
    /// The antenna's lever arm and the position's lead, fitted on the other flights.
    pub antenna: antenna::Antenna,
    /// The fused roll/pitch RMSE with the units' mounting tilt fitted on the other flights, as
    /// `--mode ahrs` scores, degrees (the mounting is the airframe's, not the flight's).
    pub fused_roll_pitch_rmse_mounted_deg: f64,
    /// The same with the mounting fitted on every flight, this one included: in sample, shown
    /// beside the held-out figure so that overfitting shows.
    pub fused_roll_pitch_rmse_mounted_in_sample_deg: f64,
    /// The held-out mounted figure over windows of time since the start (as `--mode ahrs`).
    pub fused_window_rmse_deg: WindowRmse,
    /// The fused run as given and produced, for the running service to repeat.
    #[serde(skip)]
    pub scored: Option<Box<live::ScoredGnssRun>>,
    /// The same flight through the running processes (`--live`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub live: Option<LiveFlight>,
    /// The reference checked against itself and the fused units, with the held-out mounting and
    /// antenna.
    pub reference_check: ReferenceCheck,
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
    /// The antenna fitted on every flight (in sample), beside the held-out ones in `trials`;
    /// absent when the flights do not tell it.
    pub antenna_in_sample: Option<antenna::Antenna>,
    /// Mean over flights of the fused roll/pitch RMSE with the mounting fitted on the other
    /// flights ([`FlightResult::fused_roll_pitch_rmse_mounted_deg`]), degrees.
    pub roll_pitch_rmse_mounted_deg: f64,
    /// The same with the mounting fitted on every flight (in sample), degrees.
    pub roll_pitch_rmse_mounted_in_sample_deg: f64,
    /// Window starts since the start of each run, s.
    pub window_starts_s: [f64; 3],
    /// Per window, the mean over the flights with rows in it of the held-out mounted figure.
    pub fused_window_rmse_deg: WindowRmse,
    /// The fused roll/pitch RMSE is within [`super::ROLL_PITCH_TARGET_DEG`] (`gnss` mode).
    pub roll_pitch_target_met: bool,
    /// Mean over flights of the reference's attitude change over a second against the integrated
    /// gyros, tilt per axis, degrees ([`super::reference_check`]).
    pub reference_attitude_vs_gyro_deg: f64,
    /// Mean over flights of the reference's position acceleration against its attitude and the
    /// accelerometers, tilt per axis, degrees.
    pub reference_position_vs_attitude_deg: f64,
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
    /// The ratio is within [`super::OUTAGE_RATIO_TARGET`] (`outage` mode).
    pub outage_target_met: bool,
    /// Flights listed but not evaluated, with the reason.
    pub skipped: Vec<SkippedTrial>,
    /// The same flights through the running processes (`--live`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub live: Option<LiveSummary>,
}

/// The mean of the finite values of `v`; NaN without any.
fn finite_mean(v: impl Iterator<Item = f64>) -> f64 {
    mean(&v.filter(|x| x.is_finite()).collect::<Vec<_>>())
}

pub(super) fn summarise(
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
        antenna_in_sample: None,
        roll_pitch_rmse_mounted_deg: of(&|t| t.fused_roll_pitch_rmse_mounted_deg),
        roll_pitch_rmse_mounted_in_sample_deg: of(&|t| {
            t.fused_roll_pitch_rmse_mounted_in_sample_deg
        }),
        roll_pitch_target_met: roll_pitch <= ROLL_PITCH_TARGET_DEG,
        reference_attitude_vs_gyro_deg: finite_mean(
            trials
                .iter()
                .map(|t| t.reference_check.attitude_vs_gyro_deg),
        ),
        reference_position_vs_attitude_deg: finite_mean(
            trials
                .iter()
                .map(|t| t.reference_check.position_vs_attitude_deg),
        ),
        window_starts_s: windows::WINDOW_STARTS_S,
        fused_window_rmse_deg: windows::mean(trials.iter().map(|t| &t.fused_window_rmse_deg)),
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
        live: None,
    }
}
