//! One module per subcommand.

mod bench;
mod calibrate;
mod control;
mod data;
mod echo;
mod echo_readable;
mod eval;
mod eval_live;
mod fault_args;
mod geometry;
mod import;
mod inject;
mod latency;
mod mc;
mod plot;
mod probe;
mod probe_gnss;
mod probe_gnss_report;
mod probe_rates;
mod progress;
mod readmit;
mod record;
mod record_report;
mod remote;
mod replay;
mod report_out;
mod service;
mod sim;
mod status;
mod status_link;
mod sweep;
mod up;
mod up_recording;

use std::process::ExitCode;

use anyhow::Result;

use crate::cli::{
    BenchCommand, CalibrateCommand, Cli, Command, DataCommand, EvalCommand, ImportCommand,
};

pub fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Up(args) => {
            rins_runtime::logging::init("watchdog");
            up::run(&args)
        }
        Command::Service(args) => service::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Sim(args) => {
            rins_runtime::logging::init("sim");
            sim::run(&args).map(|()| ExitCode::SUCCESS)
        }
        Command::Echo {
            topic,
            count,
            timeout,
            remote,
            ..
        } if remote.remote.is_some() => {
            let wait = (timeout > 0.0).then(|| std::time::Duration::from_secs_f64(timeout));
            let remote =
                remote::Remote::of(&remote).ok_or_else(|| anyhow::anyhow!("no --remote"))?;
            remote::echo(&remote, &topic, count, wait).map(|()| ExitCode::SUCCESS)
        }
        Command::Echo {
            topic,
            count,
            csv,
            raw,
            timeout,
            ..
        } => echo::run(&topic, count, csv, raw, timeout).map(|()| ExitCode::SUCCESS),
        Command::Soak(args) => rins_soak::run(&args.into()).map(|()| ExitCode::SUCCESS),
        Command::Status {
            json,
            timeout,
            remote,
        } => match remote::Remote::of(&remote) {
            Some(r) => remote::status(&r, json, timeout),
            None => status::run(json, timeout),
        }
        .map(|()| ExitCode::SUCCESS),
        Command::Probe(args) => probe::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Inject(args) => inject::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Record(args) => record::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Replay(args) => replay::run(&args),
        Command::Readmit { channel, timeout } => {
            readmit::run(&channel, timeout).map(|()| ExitCode::SUCCESS)
        }
        Command::Latency(args) => latency::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Bench { what } => match what {
            BenchCommand::Ipc(args) => bench::run_ipc(&args).map(|()| ExitCode::SUCCESS),
            BenchCommand::Rates(args) => bench::run_rates(&args).map(|()| ExitCode::SUCCESS),
            BenchCommand::IpcReceiver {
                phase_limit,
                config,
            } => bench::run_receiver(phase_limit, &config).map(|()| ExitCode::SUCCESS),
            BenchCommand::IpcChain {
                stage,
                config,
                rate,
                samples,
                phase_limit,
            } => bench::run_chain_process(stage, &config, rate, samples, phase_limit)
                .map(|()| ExitCode::SUCCESS),
        },
        Command::Geometry { config, json } => {
            geometry::run(config.as_deref(), json).map(|()| ExitCode::SUCCESS)
        }
        Command::Eval { what } => match what {
            EvalCommand::Fdi(args) => eval::run_fdi(&args).map(|()| ExitCode::SUCCESS),
            EvalCommand::Pyshoe(args) => eval::run_pyshoe(&args).map(|()| ExitCode::SUCCESS),
            EvalCommand::Xio(args) => eval::run_xio(&args).map(|()| ExitCode::SUCCESS),
            EvalCommand::Quadrotor(args) => eval::run_quadrotor(&args).map(|()| ExitCode::SUCCESS),
            EvalCommand::GnssCaptures(args) => {
                eval::run_gnss_captures(&args).map(|()| ExitCode::SUCCESS)
            }
        },
        Command::Import { what } => match what {
            ImportCommand::Quadrotor(args) => import::run_quadrotor(&args),
            ImportCommand::Pyshoe(args) => import::run_pyshoe(&args),
        },
        Command::Data { what } => match what {
            DataCommand::Fetch(args) => data::run_fetch(&args),
            DataCommand::List(args) => data::run_list(&args),
        },
        Command::Mc(args) => mc::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Sweep(args) => sweep::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Calibrate { what } => match what {
            CalibrateCommand::Mag(args) => calibrate::run_mag(&args).map(|()| ExitCode::SUCCESS),
        },
        Command::Plot { file, out, json } => {
            plot::run(&file, &out, json).map(|()| ExitCode::SUCCESS)
        }
    }
}
