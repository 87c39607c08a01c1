//! The arguments of `rins up` and its fault schedule.

use std::path::PathBuf;

use clap::Args;

use super::ScenarioArg;

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
    /// Publish the navigation, fused IMU and health as ROS 2 topics over Zenoh, connecting to the
    /// router or peer at this endpoint (`tcp/HOST:PORT`, `tls/HOST:PORT`): enables the bridge and
    /// replaces zenoh.connect.
    #[arg(long, value_name = "ENDPOINT")]
    pub zenoh: Option<String>,
    /// The same, listening on this endpoint for routers and peers instead (replaces
    /// zenoh.listen).
    #[arg(long, value_name = "ENDPOINT")]
    pub zenoh_listen: Option<String>,
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
    /// How the deployment uses the CPUs: `shared` runs `[wait]` and `[realtime]` as configured;
    /// `dedicated` gives acquisition, fusion and the primary navigator lane a CPU each (the
    /// highest-numbered of this process's affinity mask; at least 4 needed) at SCHED_FIFO, fusion
    /// and the navigator spinning, and confines everything else to the remaining CPUs, memory
    /// locked; `auto` is `dedicated` when at least 4 CPUs are free (usable CPUs minus the
    /// 1-minute load average, rounded up), else `shared`.
    #[arg(long, value_enum, value_name = "PROFILE", default_value = "shared")]
    pub profile: RequestedProfile,
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

/// What `--profile` asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum RequestedProfile {
    /// `[wait]` and `[realtime]` as configured.
    #[default]
    Shared,
    /// A CPU of its own for acquisition, fusion and the primary navigator lane.
    Dedicated,
    /// `dedicated` when enough CPUs are free, else `shared`.
    Auto,
}

impl RequestedProfile {
    /// The name as the command line spells it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Shared => "shared",
            Self::Dedicated => "dedicated",
            Self::Auto => "auto",
        }
    }
}
