//! `rins`: one executable, one subcommand per process kind and tool. Each service still runs as its
//! own OS process (`rins service NAME`), started and supervised by `rins up`.

mod commands;

use rins::{cli, config};

use clap::Parser;

fn main() -> std::process::ExitCode {
    let cli = cli::Cli::parse();
    match commands::run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("rins: error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}
