//! The bare three-process chain of `rins bench ipc`: the pipeline's data path with nothing of the
//! pipeline in it. A source process paced at the block's rate (as acquisition is by the serial
//! line) publishes `RawImu`; a relay waits for it and publishes `FusedImu` (fusion's place); a
//! second relay waits for that and publishes `NavState` on the primary lane's topic (the
//! navigator's place). Each stamps the header as its pipeline stage does, on the same topic names
//! and service settings, and each relay waits the way the configuration's `[wait]` says its
//! stage waits. So "serial rx -> nav state published" of the chain is the floor under the
//! pipeline's end-to-end figure on this machine and this wait strategy: two wake-ups and two
//! hops, no work, no standby lane, no watchdog.
//!
//! A phase ends with a sample whose sequence number is [`END_OF_PHASE`]; every relay forwards it
//! and ends.

use std::io::{BufReader, Write};
use std::path::Path;
use std::process::Stdio;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{FusedImu, NavState, RawImu, Stage, names};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicPublisher, TopicSubscriber};
use rins_runtime::payload::Stamped;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::wait_strategy::WaitStrategy;

use super::bare_hop::{self, END_OF_PHASE};
use super::deployment::{ChildGuard, Deployment};
use crate::cli::BenchIpcArgs;
pub use crate::cli::ChainStage;
use crate::commands::latency::{END_TO_END, HopReport, PathHops, TailRecorder};
use rins_runtime::ipc::{IpcSettings, create_node};

/// The longest sleep of a relay waiting for input: how often it looks at the stop flag.
const WAIT: Duration = Duration::from_millis(50);

/// Runs one relay until the end of the phase (or `limit`, or a stop): says `ready` on stdout once
/// its ports are made, so the bench starts the source only when the whole chain listens.
pub fn relay(
    node: &IpcNode,
    stage: ChainStage,
    strategy: WaitStrategy,
    shutdown: &Shutdown,
    limit: Duration,
) -> Result<()> {
    match stage {
        ChainStage::Source => bail!("the source is not a relay"),
        ChainStage::Fusion => relay_topics(
            node,
            (names::RAW_IMU, names::FUSED_IMU),
            Stage::Fusion,
            |raw: &RawImu| FusedImu {
                header: raw.header,
                ..FusedImu::default()
            },
            (strategy, shutdown, limit),
        ),
        ChainStage::Navigator => relay_topics(
            node,
            (names::FUSED_IMU, names::NAV_LANES[0]),
            Stage::Navigator,
            |fused: &FusedImu| NavState {
                header: fused.header,
                ..NavState::default()
            },
            (strategy, shutdown, limit),
        ),
    }
}

fn relay_topics<I, O>(
    node: &IpcNode,
    (input, output): (&'static str, &'static str),
    stage: Stage,
    convert: impl Fn(&I) -> O,
    (strategy, shutdown, limit): (WaitStrategy, &Shutdown, Duration),
) -> Result<()>
where
    I: Stamped + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend + Copy + 'static,
    O: Stamped + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend + Copy + 'static,
{
    let sub = TopicSubscriber::<I>::new(node, input)?;
    let publisher = TopicPublisher::<O>::new(node, output)?;
    say("ready")?;
    let give_up = Instant::now() + limit;
    loop {
        if shutdown.requested() || Instant::now() > give_up {
            bail!("{input}: the chain's phase did not end");
        }
        strategy.wait(&sub, WAIT)?;
        while let Some(sample) = sub.receive()? {
            let mut out = convert(&sample);
            out.header_mut().stamp(stage, monotonic_ns());
            publisher.publish(out)?;
            if sample.header().origin_seq == END_OF_PHASE {
                return Ok(());
            }
        }
    }
}

/// The source: `samples` samples of `RawImu` at `rate_hz`, each stamped as received and
/// published the instant it is sent, then the end of the phase.
pub fn source(node: &IpcNode, rate_hz: f64, samples: u64, shutdown: &Shutdown) -> Result<()> {
    let publisher = TopicPublisher::<RawImu>::new(node, names::RAW_IMU)?;
    bare_hop::publish_paced(&publisher, rate_hz, 1..=samples, true, shutdown)
}

fn say(line: &str) -> Result<()> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}")?;
    out.flush()?;
    Ok(())
}

/// The bare chain: the relays first (each says when it listens), then the source; this process
/// reads the last relay's output as the pipeline's consumer does and records the same hops.
pub fn measure_chain(
    deployment: &Deployment,
    args: &BenchIpcArgs,
    config: &Path,
    samples: u64,
    (shutdown, tail): (&Shutdown, &mut TailRecorder),
) -> Result<Vec<HopReport>> {
    let phase_limit = format!("{}", args.seconds * 3.0 + 30.0);
    let (config, rate, count) = (
        config.to_string_lossy(),
        format!("{}", args.rate),
        format!("{samples}"),
    );
    let start = |stage: &str| -> Result<ChildGuard> {
        let child = deployment
            .command(&[
                "bench",
                "ipc-chain",
                "--stage",
                stage,
                "--config",
                &config,
                "--rate",
                &rate,
                "--samples",
                &count,
                "--phase-limit",
                &phase_limit,
            ])?
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .with_context(|| format!("cannot start the chain's {stage}"))?;
        Ok(ChildGuard {
            child,
            grace: Duration::from_secs(2),
        })
    };
    let node = create_node("bench-chain-consumer", &deployment.settings)?;
    let out = rins_runtime::ipc::TopicSubscriber::<ipc_types::NavState>::new(
        &node,
        ipc_types::names::NAV_LANES[0],
    )?;
    let mut relays = Vec::new();
    for stage in ["navigator", "fusion"] {
        let mut guard = start(stage)?;
        let stdout = guard.child.stdout.take().context("a relay's stdout")?;
        bare_hop::expect_line(&mut BufReader::new(stdout), "ready")?;
        relays.push(guard);
    }
    let mut source = start("source")?;
    let mut hops = PathHops::new()?;
    let give_up = Instant::now() + Duration::from_secs_f64(args.seconds * 3.0 + 30.0);
    'measure: loop {
        if shutdown.requested() || Instant::now() > give_up {
            bail!("the bare chain did not end");
        }
        out.wait(Duration::from_millis(50))?;
        while let Some(s) = out.receive()? {
            if s.header.origin_seq == bare_hop::END_OF_PHASE {
                break 'measure;
            }
            hops.record(&s, rins_runtime::clock::monotonic_ns());
            tail.record(&s);
        }
    }
    for guard in relays.iter_mut().chain(std::iter::once(&mut source)) {
        let status = guard.child.wait()?;
        if !status.success() {
            bail!("a process of the bare chain ended with {status}");
        }
    }
    let reports = hops.reports();
    if reports[END_TO_END].samples == 0 {
        bail!("the bare chain delivered no sample");
    }
    Ok(reports)
}

/// `rins bench ipc-chain`: one process of the bare chain.
pub fn run_chain_process(
    stage: ChainStage,
    config: &Path,
    rate_hz: f64,
    samples: u64,
    phase_limit_s: f64,
) -> Result<()> {
    if !(rate_hz.is_finite() && (1.0..=16_000.0).contains(&rate_hz)) {
        bail!("--rate {rate_hz}: must be 1..=16000 Hz");
    }
    let config = crate::config::load(Some(config))?;
    let shutdown = Shutdown::install()?;
    let settings = IpcSettings::from_env();
    let node = create_node(&format!("bench-chain-{}", stage.service()), &settings)?;
    match stage {
        ChainStage::Source => source(&node, rate_hz, samples, &shutdown),
        relay => self::relay(
            &node,
            relay,
            config.wait.for_service(relay.service()),
            &shutdown,
            Duration::from_secs_f64(phase_limit_s),
        ),
    }
}
