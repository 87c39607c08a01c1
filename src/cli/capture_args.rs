//! The options of `rins record`, `rins replay`, `rins latency` and `rins bench`: recordings
//! made and played back, and the pipeline's timing measured.

use std::path::PathBuf;

use clap::{Args, Subcommand};

/// The short names the topic table marks as recordable, with their place in a recording.
macro_rules! record_short_names {
    ($($rank:literal $short:literal $constant:ident $payload:ident $kind:ident;)+) => {
        [$(($rank, $short)),+]
    };
}

/// The `--topics` help: every recordable topic's short name, in the order a recording holds them.
fn record_topics_help() -> String {
    let mut ranked = ipc_types::for_each_topic!(record => record_short_names);
    ranked.sort_by_key(|(rank, _)| *rank);
    let names: Vec<&str> = ranked.iter().map(|(_, short)| *short).collect();
    format!(
        "Comma-separated short names of the topics to record (default: all): {}",
        names.join(", ")
    )
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
    /// Short names of the topics to record (the help lists them from the topic table).
    #[arg(long, value_delimiter = ',', help = record_topics_help())]
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
        /// The bench's configuration, whose `[wait]` the receiver follows.
        #[arg(long)]
        config: PathBuf,
    },
    /// One process of the bare chain (started by `rins bench ipc`).
    #[command(hide = true)]
    IpcChain {
        /// Which process of the chain.
        #[arg(long, value_enum)]
        stage: ChainStage,
        /// The bench's configuration, whose `[wait]` a relay follows.
        #[arg(long)]
        config: PathBuf,
        /// The source's rate, Hz.
        #[arg(long, default_value_t = 1000.0)]
        rate: f64,
        /// The source's sample count.
        #[arg(long, default_value_t = 0)]
        samples: u64,
        /// Longest wait for the phase to end, s.
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
    /// How every stage waits for its input, in the bare hops, the bare chain and the pipeline
    /// alike (default: the configuration's `[wait]`).
    #[arg(long, value_enum)]
    pub wait: Option<crate::wait_config::WaitKind>,
    /// Configuration of the pipeline (default: the built-in configuration); its `[wait]` is
    /// the bare measurements' too.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// One JSON object as the last line of stdout instead of the table.
    #[arg(long)]
    pub json: bool,
}

/// Which process of the chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ChainStage {
    /// Paced publisher of `RawImu`, stamped as received and as published by acquisition.
    Source,
    /// `RawImu` in, `FusedImu` out, stamped as fusion.
    Fusion,
    /// `FusedImu` in, `NavState` on the primary lane out, stamped as the navigator.
    Navigator,
}

impl ChainStage {
    /// The pipeline stage whose `[wait]` entry this relay follows.
    pub fn service(self) -> &'static str {
        match self {
            ChainStage::Source => "acquisition",
            ChainStage::Fusion => "fusion",
            ChainStage::Navigator => "navigator",
        }
    }
}
