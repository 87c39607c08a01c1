//! One module per subcommand.

mod echo;
mod latency;
mod service;
mod sim;
mod up;

use std::process::ExitCode;

use anyhow::Result;

use crate::cli::{Cli, Command};

pub fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Up(args) => {
            rins_runtime::logging::init("watchdog");
            up::run(&args)
        }
        Command::Service { name, config, port } => {
            service::run(name, config.as_deref(), port).map(|()| ExitCode::SUCCESS)
        }
        Command::Sim(args) => {
            rins_runtime::logging::init("sim");
            sim::run(&args).map(|()| ExitCode::SUCCESS)
        }
        Command::Echo { topic, count, csv } => {
            echo::run(&topic, count, csv).map(|()| ExitCode::SUCCESS)
        }
        Command::Latency { seconds, json } => {
            latency::run(seconds, json).map(|()| ExitCode::SUCCESS)
        }
    }
}
