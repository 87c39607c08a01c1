//! Command-line interface.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

#[derive(Debug, Parser)]
#[command(
    name = "rins",
    version,
    about = "Redundant inertial navigation service"
)]
/// The parsed command line of the `rins` executable.
pub struct Cli {
    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands: one per process kind and tool.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Start the whole pipeline (simulator unless --port, every service) under the watchdog.
    Up(UpArgs),
    /// Run one service in this process (the watchdog starts each service this way).
    Service {
        /// The service to run.
        name: ServiceName,
        /// Configuration file (default: the built-in configuration).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Serial device for acquisition, or for the gnss service its receiver (overrides
        /// acquisition.port or gnss.port).
        #[arg(long)]
        port: Option<String>,
        /// MAVLink endpoint for the mavlink service (overrides mavlink.endpoints).
        #[arg(long, value_name = "ENDPOINT")]
        mavlink: Option<String>,
        /// A GNSS receiver is fitted: turns on `[gnss]`, `[navigator.gnss]` and `[sim.gnss]`.
        #[arg(long)]
        gnss: bool,
        /// IMU sample rate, Hz (overrides device.imu_rate_hz).
        #[arg(long, value_name = "HZ")]
        imu_rate: Option<f64>,
        /// Ask for the `[realtime]` settings (as `realtime.enabled = true`).
        #[arg(long)]
        realtime: bool,
    },
    /// Run the device simulator on a pseudo-terminal.
    Sim(SimArgs),
    /// Randomised faults under a running pipeline (SIGKILLs, hangs, sensor-channel faults, serial
    /// unplugs); JSON summary of kills, restarts, lost navigation samples per fault kind, the
    /// longest output gap and leaked shared memory.
    Soak(SoakArgs),
    /// The watchdog's report on every process: state, pid, restarts, heartbeat age, output rate.
    Status {
        /// One JSON object instead of the table.
        #[arg(long)]
        json: bool,
        /// Fail when no report arrives within this many seconds.
        #[arg(long, allow_negative_numbers = true, default_value_t = 2.0)]
        timeout: f64,
    },
    /// Listen to a serial device and say what is on the line: bytes, frame types and their rates,
    /// CRC failures, malformed frames, discarded bytes, the last decode error and a verdict.
    /// With --scan, listen at each standard baud rate and say which gives valid frames (a
    /// pseudo-terminal, such as the simulator's, ignores the rate: it shows frames at every one).
    Probe(ProbeArgs),
    /// Print every sample of a topic.
    Echo {
        /// Topic: raw-imu, raw-baro, raw-mag, raw-aux, fused-imu, altitude, nav, truth, heartbeat,
        /// health.
        topic: String,
        /// Stop after this many samples.
        #[arg(long)]
        count: Option<u64>,
        /// Comma-separated values with a header line, instead of one JSON object per line.
        #[arg(long)]
        csv: bool,
        /// Print the wire form: padding, unused channel slots, enums and bit sets as numbers, no
        /// derived angles (by default: channels in use, names, roll/pitch/yaw and degrees).
        #[arg(long)]
        raw: bool,
        /// Fail when no sample arrives for this many seconds (0: wait for ever).
        #[arg(long, allow_negative_numbers = true, default_value_t = 10.0)]
        timeout: f64,
    },
    /// Inject a fault into one channel of the running simulator ("kill a sensor").
    Inject(InjectArgs),
    /// Join the running deployment and record its topics into an MCAP file (Foxglove opens it;
    /// `rins plot` draws it); stops on Ctrl-C or after --duration.
    Record(RecordArgs),
    /// Feed the raw sensor topics of a recording through a fresh deployment (fusion, altimeter and
    /// navigator run live) and compare its navigation output with the recorded one, sample for
    /// sample; `--offline` runs the same code in this process without IPC.
    Replay(ReplayArgs),
    /// Return a channel that fusion excluded to service and wait for fusion's answer: readmitted
    /// once it passed its probation against the other channels, or refused (fault still present, no
    /// such channel); exits non-zero unless it is in the solution.
    Readmit {
        /// Channel: gyro or accel followed by its 0-based index, e.g. gyro2, accel0.
        channel: String,
        /// Longest wait for fusion's answer, s (the probation is 1 s at 1 kHz by default).
        #[arg(long, allow_negative_numbers = true, default_value_t = 5.0)]
        timeout: f64,
    },
    /// Measure latency from serial receive through every stage to the navigation state.
    Latency(LatencyArgs),
    /// Benchmarks that start what they measure.
    Bench {
        /// Which benchmark.
        #[command(subcommand)]
        what: BenchCommand,
    },
    /// What the configured gyro and accelerometer geometries can do: noise per axis, parity, FDI.
    Geometry {
        /// Configuration file whose geometries are reported (default: the built-in configuration).
        #[arg(long)]
        config: Option<PathBuf>,
        /// One JSON object instead of the table.
        #[arg(long)]
        json: bool,
    },
    /// Offline evaluation on recorded data, in-process (no IPC).
    Eval {
        /// Which evaluation.
        #[command(subcommand)]
        what: EvalCommand,
    },
    /// The public recordings the evaluations use, as rins recordings: raw IMU counts and truth
    /// in MCAP, a configuration beside each (`docs/import.md`).
    Import {
        /// Which data set.
        #[command(subcommand)]
        what: ImportCommand,
    },
    /// The recorded data sets the evaluations read: fetch them from their public repositories
    /// into the layout the evaluations read, or list which are present.
    Data {
        /// What to do.
        #[command(subcommand)]
        what: DataCommand,
    },
    /// Monte Carlo comparison of the redundant block with an orthogonal triad, with a gyro kill.
    Mc(McArgs),
    /// Fault sweep: one gyro or accelerometer fault per run (bias steps, a ramp, a noise increase)
    /// injected in flight into the configured chain, in-process; detection and isolation times,
    /// attitude error while the integrity said ok, false alarms of a clean run.
    Sweep(SweepArgs),
    /// Fit sensor calibrations offline from recorded samples.
    Calibrate {
        /// Which calibration.
        #[command(subcommand)]
        what: CalibrateCommand,
    },
    /// Plot a recording: attitude, position, errors against truth, channel states, latency (PNG).
    Plot {
        /// The MCAP recording.
        file: PathBuf,
        /// Directory the PNG files are written to (created if missing).
        #[arg(long)]
        out: PathBuf,
        /// End with one JSON line: {"written": [...], "skipped": [...]}.
        #[arg(long)]
        json: bool,
    },
}

/// The calibrations `rins calibrate` fits.
#[derive(Debug, Subcommand)]
pub enum CalibrateCommand {
    /// Magnetometer hard and soft iron from samples taken while the vehicle is turned through many
    /// orientations; prints the fit and a `[navigator.mag_calibration]` configuration fragment.
    Mag(CalibrateMagArgs),
}

/// Options of `rins calibrate mag`.
#[derive(Debug, Args)]
pub struct CalibrateMagArgs {
    /// CSV file: the output of `rins echo raw-mag --csv`, or a `mx_ut,my_ut,mz_ut` header and rows.
    pub file: PathBuf,
    /// Local field magnitude, µT (default: mean magnitude of the samples once the hard iron is
    /// removed).
    #[arg(long, allow_negative_numbers = true)]
    pub field_ut: Option<f64>,
    /// One JSON object on stdout instead of the summary.
    #[arg(long)]
    pub json: bool,
}

/// What `rins data` does.
#[derive(Debug, Subcommand)]
pub enum DataCommand {
    /// Clone each set's public git repository (one commit, only the files used) into
    /// DIR/.sources, convert it into the layout the evaluations read and write a PROVENANCE note
    /// beside it (source, commit, licence, what was converted, where the peer figures come
    /// from); a set already complete is left as it is.
    Fetch(DataFetchArgs),
    /// Which data sets are present in the recordings directory, which are incomplete or missing.
    List(DataListArgs),
}

/// Options of `rins data fetch`.
#[derive(Debug, Args)]
pub struct DataFetchArgs {
    /// The sets to fetch: quadrotor-4imu, pyshoe-vicon, xio-gait (default: all).
    #[arg(value_name = "SET")]
    pub sets: Vec<String>,
    /// Recordings directory (default: $RINS_DATA_DIR, else data/ at the top of the repository).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// Fetch SET from another git repository (a mirror or a local copy) instead of its
    /// published one; repeatable.
    #[arg(long = "source", value_name = "SET=URL")]
    pub sources: Vec<String>,
    /// Clone the source again and build the set again even when it is complete, replacing its
    /// directory.
    #[arg(long)]
    pub force: bool,
}

/// Options of `rins data list`.
#[derive(Debug, Args)]
pub struct DataListArgs {
    /// Recordings directory (default: $RINS_DATA_DIR, else data/ at the top of the repository).
    #[arg(long)]
    pub dir: Option<PathBuf>,
    /// One JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// The data sets `rins import` converts.
#[derive(Debug, Subcommand)]
pub enum ImportCommand {
    /// The four-IMU quadrotor flights (`<group>/path_<N>/IMU_k.csv`, `GT.csv`): one redundant
    /// block of every unit's triads, UAV profile, started in the air from the truth.
    Quadrotor(ImportArgs),
    /// The pyshoe foot-mounted walks (`*.csv` with the Vicon position), pedestrian profile.
    Pyshoe(ImportArgs),
}

/// Options of `rins import`.
#[derive(Debug, Args)]
pub struct ImportArgs {
    /// Directory of the data set.
    pub dir: PathBuf,
    /// Output directory: `<run>.mcap`, `<run>.toml` (configuration) and `<run>.json` (clock
    /// offsets, repairs, scales) per run, a flight's under its group directory.
    pub out: PathBuf,
    /// Replace output files that already exist (refused otherwise).
    #[arg(long)]
    pub force: bool,
    /// End with one JSON object instead of the summary.
    #[arg(long)]
    pub json: bool,
}

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
    /// With `--mode ahrs`: run each flight's scored fused solution again through the running
    /// processes (fusion and the navigator lanes, a private deployment per flight) and report
    /// their figures beside the in-process ones.
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

/// Options of `rins mc`.
#[derive(Debug, Args)]
pub struct McArgs {
    /// Number of runs (default: the comparison's default).
    #[arg(long)]
    pub runs: Option<usize>,
    /// Flight time simulated, s (default: the scenario's whole flight; 600 s for the static and
    /// calibrate scenarios, which never end).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Time of the gyro kill, s (default 300 s, or half the flight when --duration is shorter).
    #[arg(long, allow_negative_numbers = true)]
    pub kill_at: Option<f64>,
    /// Worker threads.
    #[arg(long)]
    pub threads: Option<usize>,
    /// One JSON object on stdout instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Configuration file (its sim, navigator and altimeter settings are used).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Simulator scenario both blocks fly (default: uav, whatever the configuration names).
    #[arg(long)]
    pub scenario: Option<ScenarioArg>,
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

/// A service `rins service` can run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ServiceName {
    /// Serial acquisition: decodes the sensor block's frames and publishes raw samples.
    Acquisition,
    /// Redundancy fusion with fault detection and isolation.
    Fusion,
    /// Barometric altitude filter.
    Altimeter,
    /// The primary navigator lane.
    Navigator,
    /// The hot-standby navigator lane.
    NavigatorStandby,
    /// The MAVLink 2 output over UDP or a serial port (`[mavlink]`).
    Mavlink,
    /// GNSS receiver acquisition (`[gnss]`): publishes one fix per receiver epoch.
    Gnss,
}

impl ServiceName {
    /// The service kind the watchdog and the health report know it by.
    pub fn kind(self) -> ipc_types::ServiceKind {
        match self {
            ServiceName::Acquisition => ipc_types::ServiceKind::Acquisition,
            ServiceName::Fusion => ipc_types::ServiceKind::Fusion,
            ServiceName::Altimeter => ipc_types::ServiceKind::Altimeter,
            ServiceName::Navigator => ipc_types::ServiceKind::Navigator,
            ServiceName::NavigatorStandby => ipc_types::ServiceKind::NavigatorStandby,
            ServiceName::Mavlink => ipc_types::ServiceKind::Mavlink,
            ServiceName::Gnss => ipc_types::ServiceKind::Gnss,
        }
    }
}

/// A simulator scenario, as the command line names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ScenarioArg {
    /// Parked level at the origin.
    Static,
    /// A small UAV's flight: take-off, circuits with banked turns, landing.
    Uav,
    /// A foot-mounted sensor walked round a rectangle.
    Walk,
    /// Turned on the spot through every orientation, the magnetometer distorted by hard and soft
    /// iron (`[sim.calibration]`): data for `rins calibrate mag`.
    Calibrate,
    /// A quadrotor: take-off, hover, sharp turns, speed changes and a gust, landing; rotor drag
    /// and rotor vibration (`[sim.multirotor]`).
    Multirotor,
}

impl From<ScenarioArg> for rins_sim::Scenario {
    fn from(scenario: ScenarioArg) -> Self {
        match scenario {
            ScenarioArg::Static => Self::Static,
            ScenarioArg::Uav => Self::Uav,
            ScenarioArg::Walk => Self::Walk,
            ScenarioArg::Calibrate => Self::Calibrate,
            ScenarioArg::Multirotor => Self::Multirotor,
        }
    }
}

/// Options of `rins up`.
#[derive(Debug, Args)]
pub struct UpArgs {
    /// Simulator scenario (overrides sim.scenario).
    #[arg(long)]
    pub scenario: Option<ScenarioArg>,
    /// Stop after this many seconds and exit 0; non-zero when no valid frame arrived in all that
    /// time (the message names the port and what the line carried).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Print the run's summary as one JSON object, the only thing on stdout (the status lines go
    /// to stderr). Without it, a run with --duration ends with the summary as text.
    #[arg(long)]
    pub json: bool,
    /// Configuration file (default: the built-in configuration).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Read a real sensor block on this serial device instead of starting the simulator.
    #[arg(long)]
    pub port: Option<PathBuf>,
    /// Simulator random seed (overrides sim.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Stream MAVLink 2 to this endpoint (`udpout:HOST:PORT`, `udpin:ADDR:PORT` or
    /// `serial:PATH:BAUD`), enabling the MAVLink output whatever the configuration says.
    #[arg(long, value_name = "ENDPOINT")]
    pub mavlink: Option<String>,
    /// A GNSS receiver is fitted: runs the gnss service (on the simulated receiver unless
    /// `[gnss] port` names one) and turns on the navigator's GNSS updates.
    #[arg(long)]
    pub gnss: bool,
    /// IMU sample rate of the simulated block and every stage, Hz (overrides
    /// device.imu_rate_hz).
    #[arg(long, value_name = "HZ")]
    pub imu_rate: Option<f64>,
    /// Every service asks for its `[realtime]` settings (SCHED_FIFO priority, CPU affinity,
    /// locked memory; as `realtime.enabled = true`); what the system refuses is logged and the
    /// service runs on without it.
    #[arg(long)]
    pub realtime: bool,
    /// Record every topic into this MCAP file from the start (replaced if it exists), as
    /// `rins record` does.
    #[arg(long, value_name = "FILE")]
    pub record: Option<PathBuf>,
    /// Start neither acquisition nor the simulator: another process publishes the raw topics
    /// (`rins replay`).
    #[arg(long, hide = true)]
    pub external_source: bool,
    /// Faults for the simulator to apply.
    #[command(flatten)]
    pub faults: FaultArgs,
}

/// Faults the simulator applies at given device times.
#[derive(Debug, Args, Default)]
pub struct FaultArgs {
    /// Apply a fault at a device time (s since the simulator started): CHANNEL:KIND[=PARAM]@TIME,
    /// e.g. gyro2:dead@5s, accel1:bias=0.5@3.2s, gyro0:noise=10@2s; or unplug the serial device
    /// for SECONDS: disconnect=SECONDS@TIME, e.g. disconnect=1.5@5s. Repeatable.
    #[arg(long = "inject", value_name = "SPEC")]
    pub inject: Vec<String>,
    /// Scenario file of timed faults: [[fault]] tables with channel, kind, at_s and optional param.
    #[arg(long, value_name = "FILE")]
    pub faults: Option<PathBuf>,
}

impl FaultArgs {
    /// Whether no fault was asked for.
    pub fn is_empty(&self) -> bool {
        self.inject.is_empty() && self.faults.is_none()
    }
}

/// Options of `rins probe`.
#[derive(Debug, Args)]
pub struct ProbeArgs {
    /// The serial device, e.g. /dev/ttyUSB0.
    #[arg(long)]
    pub port: PathBuf,
    /// Line speed, baud (default: acquisition.baud of the built-in configuration, 921600).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub baud: Option<u32>,
    /// How long to listen, s (> 0, <= 3600); with --scan, at each rate (default 3, with --scan 1).
    #[arg(long, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Try the standard baud rates, 9600 to 921600, then 1500000, 2000000 and 3000000 where the
    /// driver accepts them, and say which gives valid frames. A pseudo-terminal ignores the rate,
    /// so on one every rate shows frames.
    #[arg(long, conflicts_with = "baud")]
    pub scan: bool,
    /// One JSON object on stdout instead of the report.
    #[arg(long)]
    pub json: bool,
}

/// Options of `rins inject`.
#[derive(Debug, Args)]
pub struct InjectArgs {
    /// Channel: gyro or accel followed by its 0-based index, e.g. gyro2, accel0; `disconnect`
    /// to unplug the whole serial device for --duration seconds; or `gnss` for the simulated
    /// GNSS receiver.
    pub channel: String,
    /// dead | stuck | bias | ramp | noise | saturate | intermittent | clear; for gnss: outage |
    /// jump | freeze | drift | clear.
    pub fault: Option<String>,
    /// bias: STEP (rad/s, m/s²); ramp: RATE (per s); noise: FACTOR (>= 1, times the configured
    /// white noise); intermittent: PERIOD_S (default 0.2, dead for the first half); gnss outage
    /// and freeze: SECONDS (default: until cleared); gnss jump: METRES north; gnss drift: M_PER_S
    /// north.
    #[arg(allow_negative_numbers = true)]
    pub arg: Option<String>,
    /// disconnect: seconds the device stays unplugged (> 0, <= 3600); frames of that time are lost.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub duration: Option<String>,
}

/// Options of `rins sim`.
#[derive(Debug, Args)]
pub struct SimArgs {
    /// Simulator scenario (overrides sim.scenario).
    #[arg(long)]
    pub scenario: Option<ScenarioArg>,
    /// Simulator random seed (overrides sim.seed).
    #[arg(long)]
    pub seed: Option<u64>,
    /// IMU sample rate, Hz (overrides device.imu_rate_hz).
    #[arg(long, value_name = "HZ")]
    pub imu_rate: Option<f64>,
    /// Configuration file (default: the built-in configuration).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Also make this path a symbolic link to the pseudo-terminal (replaced if it exists).
    #[arg(long)]
    pub link: Option<PathBuf>,
    /// Simulate the GNSS receiver too (`[sim.gnss]`), its terminal also reachable under this
    /// path.
    #[arg(long, value_name = "PATH")]
    pub gnss_link: Option<PathBuf>,
    /// Stop after this many seconds (the uav and multirotor scenarios then fly their circuits or
    /// pattern for that long).
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Uav and multirotor scenarios: length of the flight, s, its circuits (pattern) repeated as
    /// many times as fit (overrides sim.uav_flight_s; default: --duration).
    #[arg(long, allow_negative_numbers = true, value_name = "SECONDS")]
    pub flight_s: Option<f64>,
    /// Faults for the simulator to apply.
    #[command(flatten)]
    pub faults: FaultArgs,
}

/// Options of `rins soak`.
#[derive(Debug, Clone, clap::Args)]
pub struct SoakArgs {
    /// How long to run, minutes.
    #[arg(long, allow_negative_numbers = true)]
    pub minutes: f64,
    /// Seed of the fault schedule.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Shortest time between two faults, s.
    #[arg(
        long = "min-interval",
        allow_negative_numbers = true,
        default_value_t = 2.0
    )]
    pub min_interval_s: f64,
    /// Longest time between two faults, s.
    #[arg(
        long = "max-interval",
        allow_negative_numbers = true,
        default_value_t = 6.0
    )]
    pub max_interval_s: f64,
    /// Kinds of fault, comma-separated: kill (SIGKILL a service), hang (SIGSTOP a service until
    /// the watchdog replaces it), sensor (fault one gyro or accelerometer channel, then clear and
    /// readmit it), disconnect (unplug the serial device for 0.2-1 s).
    #[arg(long, default_value = "kill,sensor")]
    pub faults: String,
    /// Print the summary as one JSON object on stdout (progress stays on stderr).
    #[arg(long)]
    pub json: bool,
}

impl From<SoakArgs> for rins_soak::SoakArgs {
    fn from(a: SoakArgs) -> Self {
        Self {
            minutes: a.minutes,
            seed: a.seed,
            min_interval_s: a.min_interval_s,
            max_interval_s: a.max_interval_s,
            faults: a.faults,
            json: a.json,
        }
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    use super::Cli;

    /// `rins --help` is the operator's map: every command, at every depth, says what it does (a
    /// doc comment that drifts onto the next command leaves its own command without one).
    #[test]
    fn every_command_says_what_it_does() {
        fn check(cmd: &clap::Command, path: &str) {
            for sub in cmd.get_subcommands().filter(|s| s.get_name() != "help") {
                let path = format!("{path} {}", sub.get_name());
                let about = sub.get_about().map(|a| a.to_string()).unwrap_or_default();
                assert!(!about.trim().is_empty(), "`{path}` has no description");
                check(sub, &path);
            }
        }
        Cli::command().debug_assert();
        check(&Cli::command(), "rins");
    }

    #[test]
    fn every_scenario_parses_from_the_command_line() {
        use clap::Parser;
        let parsed = Cli::try_parse_from(["rins", "up", "--scenario", "multirotor"]).unwrap();
        let super::Command::Up(up) = parsed.command else {
            panic!("not `up`: {parsed:?}");
        };
        let scenario = up.scenario.expect("--scenario given");
        assert_eq!(
            rins_sim::Scenario::from(scenario),
            rins_sim::Scenario::Multirotor
        );
        let mc = Cli::try_parse_from(["rins", "mc", "--scenario", "multirotor"]).unwrap();
        assert!(matches!(mc.command, super::Command::Mc(_)));
        assert!(Cli::try_parse_from(["rins", "up", "--scenario", "quadcopter"]).is_err());
    }
}

/// `rins record FILE`.
#[derive(Debug, Args)]
pub struct RecordArgs {
    /// The MCAP file to write (refused if it exists, unless --overwrite).
    #[arg(required_unless_present = "dir", conflicts_with = "dir")]
    pub file: Option<PathBuf>,
    /// Record into numbered files in this directory instead, a new one each --max-file-mb, the
    /// oldest of rins's own deleted past --max-total-mb (as `[record]` of `rins up`).
    #[arg(long, value_name = "DIR")]
    pub dir: Option<PathBuf>,
    /// With --dir: a file this large, MB, is closed and the next one started (default 256).
    #[arg(long, value_name = "MB", requires = "dir")]
    pub max_file_mb: Option<u64>,
    /// With --dir: the most rins's own recordings in DIR may take together, MB (default 2048).
    #[arg(long, value_name = "MB", requires = "dir")]
    pub max_total_mb: Option<u64>,
    /// Comma-separated short names of the topics to record (default: all): raw-imu, raw-baro,
    /// raw-mag, raw-aux, fused-imu, altitude, nav, nav-standby, truth, health, heartbeat, fault,
    /// sim-control, fusion-control, fusion-reply.
    #[arg(long, value_delimiter = ',')]
    pub topics: Vec<String>,
    /// Stop after this many seconds.
    #[arg(long, allow_negative_numbers = true)]
    pub duration: Option<f64>,
    /// Replace FILE if it exists (a symbolic link is replaced, never followed).
    #[arg(long)]
    pub overwrite: bool,
    /// Print one JSON summary object as the last line (`samples_written`, `samples_dropped`, ...).
    #[arg(long)]
    pub json: bool,
    /// Create this file once every topic is subscribed (for `rins up --record`).
    #[arg(long, hide = true)]
    pub ready_file: Option<PathBuf>,
}

/// `rins replay FILE`.
#[derive(Debug, Args)]
pub struct ReplayArgs {
    /// The MCAP file (`rins record`, `rins up --record`).
    pub file: PathBuf,
    /// Replay at this multiple of the recorded pace (default 1).
    #[arg(
        long,
        allow_negative_numbers = true,
        conflicts_with = "as_fast_as_possible"
    )]
    pub speed: Option<f64>,
    /// Replay as fast as the pipeline takes it (paced by its output, never losing a sample).
    #[arg(long)]
    pub as_fast_as_possible: bool,
    /// Run the services' library code in this process, without IPC, for batch analysis.
    #[arg(long)]
    pub offline: bool,
    /// Configuration file of the replaying deployment (default: the built-in configuration).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Print one JSON summary object as the last line (`nav_samples_compared`,
    /// `nav_samples_different`, ...).
    #[arg(long)]
    pub json: bool,
}

/// `rins latency`.
#[derive(Debug, Args)]
pub struct LatencyArgs {
    /// How long to measure, s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 5.0)]
    pub seconds: f64,
    /// One JSON object instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write every sample's path as Chrome Trace Event JSON (opens in the Perfetto UI): one
    /// track per process, one flow arrow per sample from serial receive to this consumer.
    #[arg(long, value_name = "FILE.json")]
    pub trace: Option<PathBuf>,
    /// Also write HDR histogram interval logs, one histogram per hop and interval (ns).
    #[arg(long, value_name = "FILE")]
    pub hdr: Option<PathBuf>,
    /// Length of one HDR log interval, s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1.0)]
    pub hdr_interval: f64,
    /// Replace the trace or HDR file if it exists (a symbolic link is replaced, never followed).
    #[arg(long)]
    pub overwrite: bool,
}

/// `rins bench` benchmarks.
#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// Every IPC hop of the pipeline against the bare iceoryx2 hop with the same payload, the
    /// same service settings and the same wait strategy, measured in one invocation.
    Ipc(BenchIpcArgs),
    /// The pipeline at each IMU rate: a fault-free run (false alarms, drops, CPU, end-to-end
    /// latency) and runs with injected faults (detected, isolated, how fast); one JSON row per
    /// rate with --json.
    Rates(BenchRatesArgs),
    /// The receiving process of the bare hops (started by `rins bench ipc`).
    #[command(hide = true)]
    IpcReceiver {
        /// Longest wait for a phase to end, s.
        #[arg(long, default_value_t = 60.0)]
        phase_limit: f64,
    },
}

/// `rins bench rates`.
#[derive(Debug, Args)]
pub struct BenchRatesArgs {
    /// IMU rates, Hz, comma-separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_values_t = [100.0, 250.0, 500.0, 1000.0, 2000.0, 4000.0, 8000.0]
    )]
    pub rates: Vec<f64>,
    /// Length of each `rins up` run (device time), s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 25.0)]
    pub duration: f64,
    /// Configuration file (default: the built-in configuration).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// One JSON object per rate, one per line, instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// `rins bench ipc`.
#[derive(Debug, Args)]
pub struct BenchIpcArgs {
    /// Length of each measurement (each bare payload, then the pipeline), s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 10.0)]
    pub seconds: f64,
    /// Sample rate of the bare hops and of the pipeline's IMU, Hz.
    #[arg(long, allow_negative_numbers = true, default_value_t = 1000.0)]
    pub rate: f64,
    /// Time the pipeline runs after its first navigation output before it is measured, s.
    #[arg(long, allow_negative_numbers = true, default_value_t = 5.0)]
    pub warmup: f64,
    /// One JSON object as the last line of stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}
