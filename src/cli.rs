//! Command-line interface.

use std::path::PathBuf;

use clap::{Args, Parser, Subcommand, ValueEnum};

#[derive(Debug, Parser)]
#[command(
    name = "rins",
    version,
    about = "Redundant inertial navigation service"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Start the whole pipeline (simulator unless --port, every service) under the watchdog.
    Up(UpArgs),
    /// Run one service in this process (the watchdog starts each service this way).
    Service {
        name: ServiceName,
        #[arg(long)]
        config: Option<PathBuf>,
        /// Serial device for acquisition (overrides acquisition.port).
        #[arg(long)]
        port: Option<String>,
    },
    /// Run the device simulator on a pseudo-terminal.
    Sim(SimArgs),
    /// Print every sample of a topic.
    Echo {
        /// Topic: raw-imu, raw-baro, raw-mag, raw-aux, fused-imu, altitude, nav, truth, health.
        topic: String,
        /// Stop after this many samples.
        #[arg(long)]
        count: Option<u64>,
        /// Comma-separated values with a header line, instead of one JSON object per line.
        #[arg(long)]
        csv: bool,
    },
    /// Measure latency from serial receive through every stage to the navigation state.
    Latency {
        #[arg(long, default_value_t = 5.0)]
        seconds: f64,
        #[arg(long)]
        json: bool,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ServiceName {
    Acquisition,
    Fusion,
    Altimeter,
    Navigator,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum ScenarioArg {
    Static,
    Uav,
}

#[derive(Debug, Args)]
pub struct UpArgs {
    /// Simulator scenario (overrides sim.scenario).
    #[arg(long)]
    pub scenario: Option<ScenarioArg>,
    /// Stop after this many seconds and exit 0.
    #[arg(long)]
    pub duration: Option<f64>,
    /// With --duration: print a JSON summary as the last line.
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Read a real sensor block on this serial device instead of starting the simulator.
    #[arg(long)]
    pub port: Option<PathBuf>,
    /// Simulator random seed (overrides sim.seed).
    #[arg(long)]
    pub seed: Option<u64>,
}

#[derive(Debug, Args)]
pub struct SimArgs {
    #[arg(long)]
    pub scenario: Option<ScenarioArg>,
    #[arg(long)]
    pub seed: Option<u64>,
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Also make this path a symbolic link to the pseudo-terminal (replaced if it exists).
    #[arg(long)]
    pub link: Option<PathBuf>,
    /// Stop after this many seconds.
    #[arg(long)]
    pub duration: Option<f64>,
}
