//! Command-line interface.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

mod capture_args;
mod data_args;
mod eval_args;
mod remote_args;
mod up_args;

pub use capture_args::{
    BenchCommand, BenchIpcArgs, BenchRatesArgs, ChainStage, LatencyArgs, RecordArgs, ReplayArgs,
};
pub use data_args::{
    CalibrateCommand, CalibrateMagArgs, DataCommand, DataFetchArgs, DataListArgs, ImportArgs,
    ImportCommand,
};
pub use eval_args::{
    EvalCommand, EvalFdiArgs, EvalGnssCapturesArgs, EvalProfileArgs, EvalPyshoeArgs,
    EvalQuadrotorArgs, EvalXioArgs, FootMethodArg, QuadrotorMode, SweepArgs,
};
pub use remote_args::RemoteArgs;
pub use up_args::{FaultArgs, RequestedProfile, UpArgs};

/// The `rins echo` topic help: every short name it accepts, in the topic table's order.
fn echo_topics_help() -> String {
    let names: Vec<&str> = ipc_types::names::TOPICS
        .iter()
        .map(|(short, _)| *short)
        .collect();
    format!("Topic: {}", names.join(", "))
}

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

/// `rins service NAME`: the service and where its configuration comes from.
#[derive(Debug, Args)]
pub struct ServiceArgs {
    /// The service to run.
    pub name: ServiceName,
    /// Configuration file (default: the built-in configuration).
    #[arg(long, conflicts_with = "resolved_config")]
    pub config: Option<PathBuf>,
    /// The whole configuration of a deployment, as `rins up` resolved it (its file, the command
    /// line and the defaults) into a private file: read as it is, with nothing applied on top.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["port", "mavlink", "gnss", "imu_rate", "realtime"])]
    pub resolved_config: Option<PathBuf>,
    /// Serial device for acquisition, or for the gnss service its receiver (overrides
    /// acquisition.port or gnss.port).
    #[arg(long)]
    pub port: Option<String>,
    /// MAVLink endpoint for the mavlink service (overrides mavlink.endpoints).
    #[arg(long, value_name = "ENDPOINT")]
    pub mavlink: Option<String>,
    /// A GNSS receiver is fitted: turns on `[gnss]`, `[navigator.gnss]` and `[sim.gnss]`.
    #[arg(long)]
    pub gnss: bool,
    /// IMU sample rate, Hz (overrides device.imu_rate_hz).
    #[arg(long, value_name = "HZ")]
    pub imu_rate: Option<f64>,
    /// Ask for the `[realtime]` settings (as `realtime.enabled = true`).
    #[arg(long)]
    pub realtime: bool,
}

/// The subcommands: one per process kind and tool.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Start the whole pipeline (simulator unless --port, every service) under the watchdog.
    Up(UpArgs),
    /// Run one service in this process (the watchdog starts each service this way).
    Service(ServiceArgs),
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
        /// A deployment on another host instead of this one.
        #[command(flatten)]
        remote: RemoteArgs,
    },
    /// Listen to a serial device and say what is on the line: bytes, frame types and their rates,
    /// CRC failures, malformed frames, discarded bytes, the last decode error and a verdict.
    /// With --scan, listen at each standard baud rate and say which gives valid frames (a
    /// pseudo-terminal, such as the simulator's, ignores the rate: it shows frames at every one).
    /// With --gnss, the same for a GNSS receiver's line (NMEA sentences, UBX frames): epochs and
    /// their fixes, every decoder counter, the last fix and a verdict.
    Probe(ProbeArgs),
    /// Print every sample of a topic.
    Echo {
        /// Short name of the topic (the help lists them from the topic table).
        #[arg(help = echo_topics_help())]
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
        /// A deployment on another host instead of this one.
        #[command(flatten)]
        remote: RemoteArgs,
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
    /// The Zenoh bridge (`[zenoh]`): the navigation, fused IMU and health as ROS 2 topics.
    Bridge,
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
            ServiceName::Bridge => ipc_types::ServiceKind::Bridge,
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

/// Options of `rins probe`.
#[derive(Debug, Args)]
pub struct ProbeArgs {
    /// The serial device, e.g. /dev/ttyUSB0.
    #[arg(long)]
    pub port: PathBuf,
    /// Line speed, baud (default: acquisition.baud of the built-in configuration, 921600; with
    /// --gnss, gnss.baud, 115200).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub baud: Option<u32>,
    /// How long to listen, s (> 0, <= 3600); with --scan, at each rate (default 3, with --scan 1,
    /// with --gnss --scan 2: a receiver sends one burst a second).
    #[arg(long, allow_negative_numbers = true)]
    pub seconds: Option<f64>,
    /// Try the standard baud rates, 9600 to 921600, then 1500000, 2000000 and 3000000 where the
    /// driver accepts them, and say which gives valid frames. A pseudo-terminal ignores the rate,
    /// so on one every rate shows frames. With --gnss: 4800 (NMEA's own rate) to 921600, and the
    /// rate with the most used sentences and frames wins.
    #[arg(long, conflicts_with = "baud")]
    pub scan: bool,
    /// The device is a GNSS receiver: read it with the gnss service's decoder (NMEA 0183, u-blox
    /// UBX) instead of the sensor block's.
    #[arg(long)]
    pub gnss: bool,
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
    #[arg(long, conflicts_with = "resolved_config")]
    pub config: Option<PathBuf>,
    /// The whole configuration of a deployment, as `rins up` resolved it into a private file:
    /// read as it is, with no scenario, seed or rate applied on top.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["scenario", "seed", "imu_rate"])]
    pub resolved_config: Option<PathBuf>,
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
    /// The deployment profile of the `rins up` it starts (as `rins up --profile`).
    #[arg(long, value_enum, value_name = "PROFILE", default_value = "shared")]
    pub profile: RequestedProfile,
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
            profile: a.profile.name().to_string(),
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
    fn the_echo_help_names_every_topic_echo_shows() {
        let cli = Cli::command();
        let echo = cli.find_subcommand("echo").expect("`rins echo`");
        let topic = echo
            .get_arguments()
            .find(|a| a.get_id() == "topic")
            .expect("the topic argument");
        let help = topic
            .get_help()
            .map(ToString::to_string)
            .unwrap_or_default();
        let listed: Vec<&str> = help.trim_start_matches("Topic: ").split(", ").collect();
        let shorts: Vec<&str> = ipc_types::names::TOPICS.iter().map(|(s, _)| *s).collect();
        assert_eq!(listed, shorts, "{help}");
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
