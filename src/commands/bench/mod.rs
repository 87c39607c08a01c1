//! `rins bench rates` (see [`rates`]) and `rins bench ipc`: every IPC hop of the pipeline beside the bare transport hop that carries the
//! same payload, measured in one invocation on the same machine, so each hop is reported as a
//! ratio to the bare hop measured a minute before it.
//!
//! First the bare hops ([`bare_hop`]): this process publishes each payload type at the block's
//! rate to a receiver process (`rins bench ipc-receiver`). Then the bare chain ([`chain`]): three
//! processes relaying the data path's payloads with no work, measured from the same stamps as the
//! pipeline. Then the pipeline: `rins up` on the simulator, on a deployment of the bench's own
//! (prefix and root), measured after its warm-up from the header stamps as `rins latency` does.
//! All three wait the way the one configuration's `[wait]` says (`--wait` sets it for every
//! stage). Everything the bench started is stopped and its shared memory removed, whatever
//! happens.

mod bare_hop;
mod chain;
mod deployment;
mod rates;

pub use chain::run_chain_process;
pub use rates::run_rates;

use std::io::BufReader;
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::ipc::{IpcSettings, create_node};
use rins_runtime::shutdown::Shutdown;
use rins_runtime::wait_strategy::WaitStrategy;
use serde::Serialize;

use crate::cli::BenchIpcArgs;
use crate::commands::latency::{END_TO_END, HopReport, TailRecorder, TailReport, measure_hops};
use crate::config::RinsConfig;
use bare_hop::{BareHop, PHASES};
use chain::measure_chain;
use deployment::{ChildGuard, Deployment, bench_config, wait_name, write_config};

/// One pipeline hop beside its bare hop.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparedHop {
    /// The pipeline hop.
    pub hop: &'static str,
    /// The payload it carries.
    pub payload: String,
    /// Pipeline figures, µs.
    pub p50_us: f64,
    /// See `p50_us`.
    pub p99_us: f64,
    /// See `p50_us`.
    pub p999_us: f64,
    /// The bare hop's median, µs.
    pub bare_p50_us: f64,
    /// The bare hop's 99th percentile, µs.
    pub bare_p99_us: f64,
    /// `p50_us / bare_p50_us`.
    pub ratio_p50: f64,
    /// `p99_us / bare_p99_us`.
    pub ratio_p99: f64,
}

/// What `rins bench ipc --json` prints.
#[derive(Debug, Clone, Serialize)]
pub struct BenchReport {
    /// Serial receive to navigation state published, µs.
    pub e2e_p50_us: f64,
    /// See `e2e_p50_us`.
    pub e2e_p99_us: f64,
    /// See `e2e_p50_us`.
    pub e2e_p999_us: f64,
    /// The bare chain's serial rx to navigation state published, µs.
    pub chain_p50_us: f64,
    /// See `chain_p50_us`.
    pub chain_p99_us: f64,
    /// See `chain_p50_us`.
    pub chain_p999_us: f64,
    /// `e2e_p50_us / chain_p50_us`.
    pub ratio_chain_p50: f64,
    /// `e2e_p99_us / chain_p99_us`.
    pub ratio_chain_p99: f64,
    /// `e2e_p999_us / chain_p999_us`.
    pub ratio_chain_p999: f64,
    /// Every hop of the bare chain, named as the pipeline's.
    pub chain: Vec<HopReport>,
    /// The pipeline's slowest 0.1 % end to end, hop by hop.
    pub tail: Option<TailReport>,
    /// The bare chain's, the same way.
    pub chain_tail: Option<TailReport>,
    /// How the stages waited: `event`, `spin`, `hybrid` (every stage), or `mixed`.
    pub wait: String,
    /// The IPC hops against their bare hops.
    pub hops: Vec<ComparedHop>,
    /// Every pipeline hop as measured.
    pub pipeline: Vec<HopReport>,
    /// Every bare hop as measured.
    pub bare: Vec<BareHop>,
    /// Length of each measurement, s.
    pub seconds: f64,
    /// Sample rate of the bare hops and of the pipeline's block, Hz.
    pub rate_hz: f64,
}

fn ratio(a: f64, b: f64) -> f64 {
    if b > 0.0 { a / b } else { f64::NAN }
}

/// The pipeline's hops beside the bare ones of the same payload.
pub fn compare(pipeline: &[HopReport], bare: &[BareHop]) -> Vec<ComparedHop> {
    PHASES
        .iter()
        .filter_map(|phase| {
            let p = pipeline.iter().find(|h| h.hop == phase.pipeline_hop)?;
            let b = bare.iter().find(|b| b.payload == phase.payload)?;
            Some(ComparedHop {
                hop: p.hop,
                payload: b.payload.clone(),
                p50_us: p.p50_us,
                p99_us: p.p99_us,
                p999_us: p.p999_us,
                bare_p50_us: b.p50_us,
                bare_p99_us: b.p99_us,
                ratio_p50: ratio(p.p50_us, b.p50_us),
                ratio_p99: ratio(p.p99_us, b.p99_us),
            })
        })
        .collect()
}

pub fn run_ipc(args: &BenchIpcArgs) -> Result<()> {
    if !(args.seconds.is_finite() && args.seconds >= 1.0 && args.seconds <= 3600.0) {
        bail!("--seconds {}: must be 1..=3600", args.seconds);
    }
    if !(args.rate.is_finite() && (100.0..=16_000.0).contains(&args.rate)) {
        bail!("--rate {}: must be 100..=16000 Hz", args.rate);
    }
    let config = bench_config(args)?;
    let shutdown = Shutdown::install()?;
    let bare_deployment = Deployment::new("b")?;
    let config_path = write_config(&bare_deployment, &config)?;
    let samples = (args.seconds * args.rate).round() as u64;
    let wait = wait_name(&config);
    progress(&format!(
        "bare iceoryx2 hops: 3 payloads × {} s at {} Hz, wait {wait}",
        args.seconds, args.rate
    ));
    let bare = measure_bare(&bare_deployment, args, &config_path, samples, &shutdown)?;
    drop(bare_deployment);
    progress("bare chain: 3 processes relaying, no work");
    let chain_deployment = Deployment::new("c")?;
    let config_path = write_config(&chain_deployment, &config)?;
    // Room for every sample measured, and some for a pipeline that runs fast.
    let room = (samples + samples / 10 + 1000) as usize;
    let mut chain_tail = TailRecorder::new(room);
    let chain = measure_chain(
        &chain_deployment,
        args,
        &config_path,
        samples,
        (&shutdown, &mut chain_tail),
    )?;
    drop(chain_deployment);
    progress("pipeline: rins up --scenario uav, warming up");
    let deployment = Deployment::new("p")?;
    let config_path = write_config(&deployment, &config)?;
    let mut tail = TailRecorder::new(room);
    let pipeline = measure_pipeline(&deployment, args, &config_path, (&shutdown, &mut tail))?;
    let (e2e, floor) = (&pipeline[END_TO_END], &chain[END_TO_END]);
    let report = BenchReport {
        e2e_p50_us: e2e.p50_us,
        e2e_p99_us: e2e.p99_us,
        e2e_p999_us: e2e.p999_us,
        chain_p50_us: floor.p50_us,
        chain_p99_us: floor.p99_us,
        chain_p999_us: floor.p999_us,
        ratio_chain_p50: ratio(e2e.p50_us, floor.p50_us),
        ratio_chain_p99: ratio(e2e.p99_us, floor.p99_us),
        ratio_chain_p999: ratio(e2e.p999_us, floor.p999_us),
        wait,
        tail: tail.report(),
        chain_tail: chain_tail.report(),
        hops: compare(&pipeline, &bare),
        chain,
        pipeline,
        bare,
        seconds: args.seconds,
        rate_hz: args.rate,
    };
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_table(&report);
    }
    Ok(())
}

fn progress(what: &str) {
    // The JSON document is stdout's only line; progress goes to stderr either way.
    eprintln!("rins bench ipc: {what}");
}

fn measure_bare(
    deployment: &Deployment,
    args: &BenchIpcArgs,
    config: &Path,
    samples: u64,
    shutdown: &Shutdown,
) -> Result<Vec<BareHop>> {
    let phase_limit = format!("{}", args.seconds * 3.0 + 30.0);
    let config = config.to_string_lossy();
    let child = deployment
        .command(&[
            "bench",
            "ipc-receiver",
            "--phase-limit",
            &phase_limit,
            "--config",
            &config,
        ])?
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .context("cannot start the bench receiver")?;
    let mut guard = ChildGuard {
        child,
        grace: Duration::from_secs(2),
    };
    let stdout = guard.child.stdout.take().context("the receiver's stdout")?;
    let mut reader = BufReader::new(stdout);
    {
        let node = create_node("bench-publisher", &deployment.settings)?;
        bare_hop::publish(&node, &mut reader, args.rate, samples, shutdown)?;
    }
    let mut line = String::new();
    std::io::BufRead::read_line(&mut reader, &mut line).context("the receiver's figures")?;
    let bare: Vec<BareHop> = serde_json::from_str(line.trim())
        .with_context(|| format!("the receiver's figures: {line:?}"))?;
    let status = guard.child.wait()?;
    if !status.success() {
        bail!("the bench receiver ended with {status}");
    }
    Ok(bare)
}

fn measure_pipeline(
    deployment: &Deployment,
    args: &BenchIpcArgs,
    config: &Path,
    (shutdown, tail): (&Shutdown, &mut TailRecorder),
) -> Result<Vec<HopReport>> {
    // Long enough for a slow start and the measurement; stopped as soon as it is done.
    let duration = format!("{}", args.seconds + args.warmup + 300.0);
    let rate = format!("{}", args.rate);
    let up = deployment
        .command(&[
            "up",
            "--scenario",
            "uav",
            "--duration",
            &duration,
            "--imu-rate",
            &rate,
            "--config",
            &config.to_string_lossy(),
            "--json",
        ])?
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .context("cannot start rins up")?;
    let mut guard = ChildGuard {
        child: up,
        grace: Duration::from_secs(30),
    };
    let node = create_node("bench", &deployment.settings)?;
    // Wait for navigation (the start-up and the alignment), then the warm-up.
    {
        let mut nav = NavSubscriber::new(&node)?;
        let until = Instant::now() + Duration::from_secs(180);
        loop {
            if shutdown.requested() {
                bail!("stopped");
            }
            if let Ok(Some(status)) = guard.child.try_wait() {
                bail!("rins up ended before navigating: {status}");
            }
            if Instant::now() > until {
                bail!("no navigation output within 180 s of rins up");
            }
            nav.wait(Duration::from_millis(100))?;
            if nav.receive()?.is_some() {
                break;
            }
        }
    }
    std::thread::sleep(Duration::from_secs_f64(args.warmup));
    progress(&format!("pipeline: measuring {} s", args.seconds));
    let hops = measure_hops(&node, Duration::from_secs_f64(args.seconds), shutdown, tail)?;
    drop(node);
    guard.stop();
    if hops[END_TO_END].samples == 0 {
        bail!("the pipeline published no navigation state while measured");
    }
    Ok(hops)
}

fn print_table(r: &BenchReport) {
    println!(
        "{:<42} {:>9} {:>9} {:>10} {:>10} {:>8} {:>8}",
        "hop", "p50 µs", "p99 µs", "bare p50", "bare p99", "× p50", "× p99"
    );
    for h in &r.hops {
        println!(
            "{:<42} {:>9.1} {:>9.1} {:>10.1} {:>10.1} {:>8.2} {:>8.2}",
            h.hop, h.p50_us, h.p99_us, h.bare_p50_us, h.bare_p99_us, h.ratio_p50, h.ratio_p99
        );
    }
    println!(
        "serial rx -> nav state published: p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs",
        r.e2e_p50_us, r.e2e_p99_us, r.e2e_p999_us
    );
    println!(
        "bare chain (3 processes, no work, wait {}): p50 {:.1} µs, p99 {:.1} µs, p99.9 {:.1} µs; pipeline × {:.2} / {:.2} / {:.2}",
        r.wait,
        r.chain_p50_us,
        r.chain_p99_us,
        r.chain_p999_us,
        r.ratio_chain_p50,
        r.ratio_chain_p99,
        r.ratio_chain_p999
    );
    for (what, tail) in [("pipeline", &r.tail), ("bare chain", &r.chain_tail)] {
        if let Some(t) = tail {
            let hops: Vec<String> = t
                .hops
                .iter()
                .map(|h| format!("{} {:.0} µs (longest in {})", h.hop, h.mean_us, h.dominant))
                .collect();
            println!(
                "{what}'s slowest {} samples (≥ {:.0} µs): {}",
                t.samples,
                t.threshold_us,
                hops.join("; ")
            );
        }
    }
}

/// The wait strategies of the bare hops' receivers, in [`bare_hop::PHASES`] order: as the
/// pipeline stage that receives each payload (the navigation state's consumer sleeps on events).
fn receiver_strategies(config: &RinsConfig) -> [WaitStrategy; 3] {
    [
        config.wait.for_service("fusion"),
        config.wait.for_service("navigator"),
        WaitStrategy::Event,
    ]
}

/// `rins bench ipc-receiver`: the receiving end of the bare hops.
pub fn run_receiver(phase_limit_s: f64, config: &Path) -> Result<()> {
    let config = crate::config::load(Some(config))?;
    let shutdown = Shutdown::install()?;
    let settings = IpcSettings::from_env();
    let node = create_node("bench-receiver", &settings)?;
    bare_hop::receive(
        &node,
        receiver_strategies(&config),
        &shutdown,
        Duration::from_secs_f64(phase_limit_s),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hop(name: &'static str, p50: f64, p99: f64) -> HopReport {
        HopReport {
            hop: name,
            samples: 100,
            p50_us: p50,
            p99_us: p99,
            p999_us: p99 * 2.0,
            max_us: p99 * 3.0,
        }
    }

    fn bare(payload: &str, p50: f64, p99: f64) -> BareHop {
        BareHop {
            payload: payload.into(),
            bytes: 100,
            samples: 100,
            p50_us: p50,
            p99_us: p99,
            p999_us: p99,
            max_us: p99,
        }
    }

    #[test]
    fn each_ipc_hop_is_set_against_the_bare_hop_of_its_payload() {
        let pipeline = [
            hop("serial rx -> acquisition published", 1.0, 2.0),
            hop("acquisition -> fusion published", 30.0, 100.0),
            hop("fusion -> navigator published", 45.0, 90.0),
            hop("serial rx -> nav state published", 80.0, 200.0),
            hop("navigator published -> consumer received", 20.0, 50.0),
        ];
        let bare = [
            bare("NavState", 10.0, 25.0),
            bare("RawImu", 10.0, 20.0),
            bare("FusedImu", 15.0, 0.0),
        ];
        let c = compare(&pipeline, &bare);
        let rows: Vec<(&str, &str, f64)> = c
            .iter()
            .map(|h| (h.hop, h.payload.as_str(), h.ratio_p50))
            .collect();
        assert_eq!(
            rows,
            [
                ("acquisition -> fusion published", "RawImu", 3.0),
                ("fusion -> navigator published", "FusedImu", 3.0),
                ("navigator published -> consumer received", "NavState", 2.0),
            ]
        );
        assert_eq!(c[0].ratio_p99, 5.0);
        // A bare figure of zero gives no ratio rather than infinity.
        assert!(c[1].ratio_p99.is_nan());
    }

    #[test]
    fn a_missing_bare_hop_leaves_its_row_out() {
        let pipeline = [hop("acquisition -> fusion published", 30.0, 100.0)];
        assert!(compare(&pipeline, &[bare("NavState", 1.0, 1.0)]).is_empty());
    }
}
