//! `rins eval fdi|pyshoe|xio|quadrotor|gnss-captures`: loads the configuration, runs the
//! evaluation from `rins-eval` with a progress bar and prints the report.

use anyhow::{Context, Result};
use rins_eval::fdi::{FdiRequest, draw_roc, evaluate, to_table};

use rins_eval::foot::FootMethod;

use crate::cli::{
    EvalFdiArgs, EvalGnssCapturesArgs, EvalProfileArgs, EvalPyshoeArgs, EvalQuadrotorArgs,
    EvalXioArgs, FootMethodArg, QuadrotorMode,
};
use crate::config;

pub fn run_fdi(args: &EvalFdiArgs) -> Result<()> {
    let cfg = config::load(args.config.as_deref())?;
    let request = FdiRequest {
        dir: args.dir.clone(),
        trials: args.trials.clone(),
        fdi: cfg.fusion.fdi.clone(),
        lsb: [cfg.device.gyro_lsb_rps(), cfg.device.accel_lsb_mps2()],
        threads: args.threads.map_or_else(
            || std::thread::available_parallelism().map_or(1, usize::from),
            usize::from,
        ),
    };
    let mut bar = super::progress::Progress::new("eval fdi");
    let report = evaluate(&request, &mut |done, total| bar.set(done, total))?;
    bar.finish();
    if let Some(path) = &args.plot {
        draw_roc(path, &report.roc, &report.operating_points)?;
        eprintln!("eval fdi: ROC drawn in {}", path.display());
    }
    super::report_out::print_report(args.json, &report, to_table)
}

fn pedestrian(args: &EvalProfileArgs) -> Result<rins_navigator::inertial_core::AidedConfig> {
    Ok(config::load_pedestrian(args.profile.as_deref())?
        .navigator
        .aided_config())
}

fn print<T: serde::Serialize>(json: bool, report: &T, table: impl Fn(&T) -> String) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string(report)?);
    } else {
        print!("{}", table(report));
    }
    Ok(())
}

fn foot_method(m: FootMethodArg) -> FootMethod {
    match m {
        FootMethodArg::Rins => FootMethod::Rins,
        FootMethodArg::Reference => FootMethod::Reference,
    }
}

fn plotted(what: &str, dir: Option<&std::path::Path>) {
    if let Some(dir) = dir {
        eprintln!("eval {what}: one plot per trial in {}", dir.display());
    }
}

pub fn run_pyshoe(args: &EvalPyshoeArgs) -> Result<()> {
    let profile = config::load_pedestrian(args.common.profile.as_deref())?;
    let aided = profile.navigator.aided_config();
    let mut bar = super::progress::Progress::new("eval pyshoe");
    let mut progress = |d, t| bar.set(d, t);
    let options = rins_eval::foot::PyshoeOptions {
        method: foot_method(args.method),
        plot_dir: args.plot.as_deref(),
        smooth: args.smooth,
    };
    let (mut report, walks) = if args.live {
        rins_eval::foot::evaluate_pyshoe_with_runs(&args.dir, &aided, options, &mut progress)?
    } else {
        let report = rins_eval::foot::evaluate_pyshoe(&args.dir, &aided, options, &mut progress)?;
        (report, Vec::new())
    };
    bar.finish();
    if args.live {
        let text = match &args.common.profile {
            Some(path) => std::fs::read_to_string(path)
                .with_context(|| format!("cannot read {}", path.display()))?,
            None => config::PEDESTRIAN.to_string(),
        };
        super::eval_live::pyshoe(&profile, &text, &walks, &mut report)?;
    }
    plotted("pyshoe", args.plot.as_deref());
    print(
        args.common.json,
        &report,
        rins_eval::foot::report::pyshoe_table,
    )
}

pub fn run_xio(args: &EvalXioArgs) -> Result<()> {
    let aided = pedestrian(&args.common)?;
    let mut bar = super::progress::Progress::new("eval xio");
    let report = rins_eval::foot::evaluate_xio(
        &args.files,
        &aided,
        foot_method(args.method),
        args.plot.as_deref(),
        args.smooth,
        &mut |d, t| bar.set(d, t),
    )?;
    bar.finish();
    plotted("xio", args.plot.as_deref());
    print(
        args.common.json,
        &report,
        rins_eval::foot::report::xio_table,
    )
}

pub fn run_quadrotor(args: &EvalQuadrotorArgs) -> Result<()> {
    let aided = config::load_uav(args.common.profile.as_deref())?
        .navigator
        .aided_config();
    let mut bar = super::progress::Progress::new("eval quadrotor");
    if args.live && !matches!(args.mode, QuadrotorMode::Ahrs | QuadrotorMode::Gnss) {
        anyhow::bail!("eval quadrotor: --live runs --mode ahrs and --mode gnss only");
    }
    if args.live && args.mode == QuadrotorMode::Gnss {
        let (mut report, runs) = rins_eval::quadrotor_gnss::evaluate_with_runs(
            &args.dir,
            &aided,
            rins_eval::quadrotor_gnss::GnssMode::Gnss,
            &mut |d, t| bar.set(d, t),
        )?;
        bar.finish();
        super::eval_live::quadrotor_gnss(&args.dir, &runs, &mut report)?;
        return print(
            args.common.json,
            &report,
            rins_eval::quadrotor_gnss::report::to_table,
        );
    }
    if args.live {
        let (mut report, runs) =
            rins_eval::quadrotor_ahrs::evaluate_with_runs(&args.dir, &aided, &mut |d, t| {
                bar.set(d, t)
            })?;
        bar.finish();
        super::eval_live::quadrotor_ahrs(&args.dir, &runs, &mut report)?;
        return print(
            args.common.json,
            &report,
            rins_eval::quadrotor_ahrs::report::to_table,
        );
    }
    if args.mode == QuadrotorMode::Ahrs {
        let report =
            rins_eval::quadrotor_ahrs::evaluate(&args.dir, &aided, &mut |d, t| bar.set(d, t))?;
        bar.finish();
        return print(
            args.common.json,
            &report,
            rins_eval::quadrotor_ahrs::report::to_table,
        );
    }
    let gnss_mode = match args.mode {
        QuadrotorMode::Gnss => Some(rins_eval::quadrotor_gnss::GnssMode::Gnss),
        QuadrotorMode::Outage => Some(rins_eval::quadrotor_gnss::GnssMode::Outage),
        QuadrotorMode::Free | QuadrotorMode::Ahrs => None,
    };
    if let Some(mode) = gnss_mode {
        let report = rins_eval::quadrotor_gnss::evaluate(&args.dir, &aided, mode, &mut |d, t| {
            bar.set(d, t)
        })?;
        bar.finish();
        return print(
            args.common.json,
            &report,
            rins_eval::quadrotor_gnss::report::to_table,
        );
    }
    let report = rins_eval::quadrotor_nav::evaluate(&args.dir, &aided, &mut |d, t| bar.set(d, t))?;
    bar.finish();
    print(
        args.common.json,
        &report,
        rins_eval::quadrotor_nav::report::to_table,
    )
}

pub fn run_gnss_captures(args: &EvalGnssCapturesArgs) -> Result<()> {
    if args.live {
        let options = super::eval_live::GnssLiveOptions {
            baud: args.baud,
            jobs: usize::from(args.jobs),
        };
        let report = super::eval_live::gnss_captures(&args.dir, options)?;
        for failure in &report.report.failures {
            eprintln!(
                "eval gnss-captures --live: {} not evaluated: {}",
                failure.name, failure.reason
            );
        }
        return print(
            args.json,
            &report,
            rins_eval::gnss_captures::live::to_live_table,
        );
    }
    let mut bar = super::progress::Progress::new("eval gnss-captures");
    let report = rins_eval::gnss_captures::evaluate(&args.dir, &mut |d, t| bar.set(d, t))?;
    bar.finish();
    for failure in &report.failures {
        eprintln!(
            "eval gnss-captures: {} not evaluated: {}",
            failure.name, failure.reason
        );
    }
    print(args.json, &report, rins_eval::gnss_captures::to_table)
}
