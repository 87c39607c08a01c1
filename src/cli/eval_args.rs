//! The options of `rins eval` and `rins sweep`: evaluations on recorded data and the sweep of
//! injected faults over the simulated flight.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};

/// The evaluations on recorded data `rins eval` runs.
#[derive(Debug, Subcommand)]
pub enum EvalCommand {
    /// Fault detection and isolation on the four-IMU quadrotor recordings: false alarms without
    /// faults, then detection and isolation of faults injected into the real data.
    Fdi(EvalFdiArgs),
    /// Foot-mounted walks with Vicon truth: 2-D position RMSE per trial, pedestrian profile.
    Pyshoe(EvalPyshoeArgs),
    /// Foot-mounted closed-loop walks: end-point error, m and % of distance, pedestrian profile.
    Xio(EvalXioArgs),
    /// Quadrotor flights, free inertial from the truth at the start: roll/pitch RMSE and height
    /// error of each IMU alone and of the four fused, UAV profile.
    Quadrotor(EvalQuadrotorArgs),
    /// The GNSS decoder on real receivers' captures (NMEA, UBX): fix epochs published against
    /// gpsd's decode of the same bytes, matched by the receiver's time, positions compared.
    GnssCaptures(EvalGnssCapturesArgs),
}

/// Options of `rins eval gnss-captures`.
#[derive(Debug, Args)]
pub struct EvalGnssCapturesArgs {
    /// Directory of captures: `NAME.log` (`#` comment lines, then the receiver's bytes) with
    /// gpsd's decode `NAME.log.chk` beside each (crates/gnss-protocol/tests/captures).
    pub dir: PathBuf,
    /// One JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Play each capture at line pace through a pseudo-terminal to a running `rins service gnss`
    /// (a private IPC root and prefix per capture) and score the fixes it publishes, with the
    /// bytes it read and the differences to the in-process decoder's fixes.
    #[arg(long)]
    pub live: bool,
    /// With `--live`: line rate the bytes are written at, baud (10 bits per byte).
    #[arg(long, value_name = "B", default_value_t = 115_200, requires = "live",
          value_parser = clap::value_parser!(u32).range(300..=4_000_000))]
    pub baud: u32,
    /// With `--live`: captures played at once, each with its own terminal and service.
    #[arg(long, value_name = "N", default_value_t = 4, requires = "live",
          value_parser = clap::value_parser!(u16).range(1..=64))]
    pub jobs: u16,
}

/// What `rins eval quadrotor` runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum QuadrotorMode {
    /// Free-inertial from the reference at t0: no aiding at all.
    Free,
    /// The navigator's tilt updates (AHRS), cross-validated leave-one-flight-out, beside each
    /// unit alone and each unit's own on-board filter.
    Ahrs,
    /// GNSS-aided from a standard receiver made from the reference (5 Hz, σ 1.5 m / 3 m /
    /// 0.1 m/s): attitude, heading and position errors, receiver rejections.
    Gnss,
    /// As `gnss` with the receiver cut for the last 10 s: the horizontal error at the end of
    /// the outage, the fused units against each unit alone.
    Outage,
}

/// Options of `rins eval quadrotor`.
#[derive(Debug, Args)]
pub struct EvalQuadrotorArgs {
    /// Data set directory (holding `<group>/path_<N>/IMU_k.csv` and `GT.csv`).
    pub dir: PathBuf,
    /// What to run.
    #[arg(long, value_enum, default_value = "free")]
    pub mode: QuadrotorMode,
    /// With `--mode ahrs` or `--mode gnss`: run each flight's scored fused solution again through
    /// the running processes (fusion and the navigator lanes, a private deployment per flight; in
    /// gnss mode the receiver's messages on the receiver's topic) and report their figures beside
    /// the in-process ones.
    #[arg(long)]
    pub live: bool,
    /// Output format and navigator profile.
    #[command(flatten)]
    pub common: EvalProfileArgs,
}

/// The estimator a foot-mounted evaluation shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum FootMethodArg {
    /// The navigator with the pedestrian profile.
    Rins,
    /// The peer's published method: SHOE detector and zero-velocity EKF, one threshold for all
    /// trials.
    Reference,
}

/// Options of `rins eval pyshoe`.
#[derive(Debug, Args)]
pub struct EvalPyshoeArgs {
    /// Directory of trials (`*.csv`, with the peer's figures in a `.json` beside each).
    pub dir: PathBuf,
    /// The estimator whose figures, means and plots are shown (both are always run).
    #[arg(long, value_enum, default_value = "rins")]
    pub method: FootMethodArg,
    /// Write one PNG per trial into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Run each trial's held-out rins run again through the running processes (fusion and the
    /// navigator lanes, a private deployment per trial) and report their figures beside the
    /// in-process ones.
    #[arg(long)]
    pub live: bool,
    /// Also smooth each trial's held-out rins run after the fact (Rauch–Tung–Striebel over the
    /// filter's history) and report `smoothed_armse_m` beside the causal figure.
    #[arg(long)]
    pub smooth: bool,
    /// Output format and navigator profile.
    #[command(flatten)]
    pub common: EvalProfileArgs,
}

/// Options of `rins eval xio`.
#[derive(Debug, Args)]
pub struct EvalXioArgs {
    /// Walk files (`Time (s),Gyroscope X (deg/s),…` CSV).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// The estimator evaluated.
    #[arg(long, value_enum, default_value = "rins")]
    pub method: FootMethodArg,
    /// Write one PNG per walk into this directory.
    #[arg(long, value_name = "DIR")]
    pub plot: Option<PathBuf>,
    /// Also smooth each walk after the fact (Rauch–Tung–Striebel over the filter's history) and
    /// report `smoothed_end_error_m` beside the causal `end_error_m` (rins method only).
    #[arg(long)]
    pub smooth: bool,
    /// Output format and navigator profile.
    #[command(flatten)]
    pub common: EvalProfileArgs,
}

/// Options the navigation evaluations share: output format and navigator profile.
#[derive(Debug, Args)]
pub struct EvalProfileArgs {
    /// One JSON object on stdout instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Profile configuration file (its `[navigator]` settings are used; default: the command's
    /// built-in profile, config/pedestrian.toml for pyshoe and xio, config/uav.toml for
    /// quadrotor).
    #[arg(long)]
    pub profile: Option<PathBuf>,
}

/// Options of `rins eval fdi`.
#[derive(Debug, Args)]
pub struct EvalFdiArgs {
    /// Data set directory (holding `<group>/path_<N>/IMU_k.csv`).
    pub dir: PathBuf,
    /// One JSON object on stdout instead of tables.
    #[arg(long)]
    pub json: bool,
    /// Configuration file (its `[fusion.fdi]` settings are used, except those the evaluation
    /// chooses by cross-validation: false-alarm probability, noise, motion noise, timing skew,
    /// noise-outlier ratio; geometry is the evaluation's).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Only trials whose name contains this text, e.g. `Horizontal/path_1`. Repeatable.
    #[arg(long = "trial", value_name = "NAME")]
    pub trials: Vec<String>,
    /// Also draw the cross-validated ROC into this PNG file.
    #[arg(long, value_name = "FILE.png")]
    pub plot: Option<PathBuf>,
    /// Worker threads (default: the machine's cores).
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..=256))]
    pub threads: Option<u16>,
}

/// Options of `rins sweep`.
#[derive(Debug, Args)]
pub struct SweepArgs {
    /// Configuration file whose sim, fusion, altimeter and navigator settings are swept (default:
    /// the built-in configuration); the `uav` scenario is flown whatever it names.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Simulator seed of every run (default: sim.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Injection time, s of device time; repeat for several (default: 8 and 120, the ground roll
    /// and the first turn).
    #[arg(long = "at", value_name = "S", allow_negative_numbers = true)]
    pub at: Vec<f64>,
    /// Flight after each injection, s (default 45).
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub window: Option<f64>,
    /// Only this channel (gyro0 … accel3); repeat for several (default: every channel).
    #[arg(long, value_name = "CHANNEL")]
    pub channel: Vec<String>,
    /// Worker threads (default 2).
    #[arg(long)]
    pub threads: Option<usize>,
    /// One JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}
