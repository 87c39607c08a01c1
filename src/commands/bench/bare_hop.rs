//! The bare transport hop of `rins bench ipc`: one process publishes, another wakes and receives,
//! with nothing of a pipeline stage in between. Both ends are the same iceoryx2 ports the stages
//! use (`TopicPublisher`: loan, write, send, notify; `TopicSubscriber`: the listener's wait, then
//! receive), on topics of their own but with the same service settings, the same payload types
//! and the same wait strategy (the receiving stage's `[wait]`). So the ratio of a pipeline hop to its bare hop
//! is what the stage adds: its work, its other wake-ups, and the scheduler's share of them.
//!
//! The publisher paces samples at the block's rate and stamps each with its send time; the
//! receiver records receive − send. One payload type after the other: a phase ends with a sample
//! whose sequence number is [`END_OF_PHASE`], and the receiver says on its stdout when it is ready
//! for the next, so the queues never hold samples of another phase.

use std::io::{BufRead, Write};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use hdrhistogram::Histogram;
use iceoryx2::prelude::ZeroCopySend;
use ipc_types::{FusedImu, NavState, RawImu, Stage};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicPublisher, TopicSubscriber};
use rins_runtime::payload::Stamped;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::wait_strategy::WaitStrategy;
use serde::{Deserialize, Serialize};

use crate::commands::latency::latency_histogram;

/// Sequence number of the sample that ends a phase.
pub const END_OF_PHASE: u64 = u64::MAX;

/// The payloads measured, in order: what each IPC hop of the pipeline carries.
pub const PHASES: [Phase; 3] = [
    Phase {
        payload: "RawImu",
        topic: "rins-bench/raw-imu",
        pipeline_hop: "acquisition -> fusion published",
        bytes: std::mem::size_of::<RawImu>(),
    },
    Phase {
        payload: "FusedImu",
        topic: "rins-bench/fused-imu",
        pipeline_hop: "fusion -> navigator published",
        bytes: std::mem::size_of::<FusedImu>(),
    },
    Phase {
        payload: "NavState",
        topic: "rins-bench/nav-state",
        pipeline_hop: "navigator published -> consumer received",
        bytes: std::mem::size_of::<NavState>(),
    },
];

/// One payload type's bare hop.
#[derive(Debug, Clone, Copy)]
pub struct Phase {
    /// The payload type.
    pub payload: &'static str,
    /// The bench's own topic for it.
    pub topic: &'static str,
    /// The pipeline hop that carries it.
    pub pipeline_hop: &'static str,
    /// Its size, bytes.
    pub bytes: usize,
}

/// What the receiver measured in one phase, µs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BareHop {
    /// The payload type.
    pub payload: String,
    /// Its size, bytes.
    pub bytes: usize,
    /// Samples received.
    pub samples: u64,
    /// Median, µs.
    pub p50_us: f64,
    /// 99th percentile, µs.
    pub p99_us: f64,
    /// 99.9th percentile, µs.
    pub p999_us: f64,
    /// Largest, µs.
    pub max_us: f64,
}

fn bare_hop(phase: &Phase, h: &Histogram<u64>) -> BareHop {
    let r = crate::commands::latency::report_of(phase.pipeline_hop, h);
    BareHop {
        payload: phase.payload.to_string(),
        bytes: phase.bytes,
        samples: r.samples,
        p50_us: r.p50_us,
        p99_us: r.p99_us,
        p999_us: r.p999_us,
        max_us: r.max_us,
    }
}

/// The receiving process: subscribes to every phase's topic, says `ready`, then per phase waits,
/// receives and records until the phase's end, says `done PAYLOAD`; finally prints one JSON line
/// with every phase's figures.
/// `strategies` are how each phase's receiver waits, in [`PHASES`] order: as the pipeline stage
/// that receives that payload.
pub fn receive(
    node: &IpcNode,
    strategies: [WaitStrategy; 3],
    shutdown: &Shutdown,
    phase_limit: Duration,
) -> Result<()> {
    let raw = TopicSubscriber::<RawImu>::new(node, PHASES[0].topic)?;
    let fused = TopicSubscriber::<FusedImu>::new(node, PHASES[1].topic)?;
    let nav = TopicSubscriber::<NavState>::new(node, PHASES[2].topic)?;
    let mut out = std::io::stdout().lock();
    writeln!(out, "ready")?;
    out.flush()?;
    let mut results = Vec::new();
    for (phase, h) in [
        (
            &PHASES[0],
            receive_phase(&raw, strategies[0], shutdown, phase_limit)?,
        ),
        (
            &PHASES[1],
            receive_phase(&fused, strategies[1], shutdown, phase_limit)?,
        ),
        (
            &PHASES[2],
            receive_phase(&nav, strategies[2], shutdown, phase_limit)?,
        ),
    ] {
        results.push(bare_hop(phase, &h));
    }
    writeln!(out, "{}", serde_json::to_string(&results)?)?;
    Ok(())
}

fn receive_phase<T: Stamped + std::fmt::Debug + ZeroCopySend + Copy + 'static>(
    topic: &TopicSubscriber<T>,
    strategy: WaitStrategy,
    shutdown: &Shutdown,
    limit: Duration,
) -> Result<Histogram<u64>> {
    let mut h = latency_histogram()?;
    let give_up = Instant::now() + limit;
    loop {
        if shutdown.requested() || Instant::now() > give_up {
            bail!("{}: the phase did not end", topic.name());
        }
        strategy.wait(topic, Duration::from_millis(50))?;
        while let Some(sample) = topic.receive()? {
            let now = monotonic_ns();
            let header = sample.header();
            if header.origin_seq == END_OF_PHASE {
                let mut out = std::io::stdout().lock();
                writeln!(out, "done {}", topic.name())?;
                out.flush()?;
                return Ok(h);
            }
            let sent = header.stage_ns(Stage::Acquisition);
            if sent != 0 && now >= sent {
                h.saturating_record((now - sent).max(1));
            }
        }
    }
}

/// The publishing side: per phase, `samples` samples at `rate_hz`, each stamped just before it
/// is sent, then the end of the phase; waits for the receiver's word between phases.
pub fn publish(
    node: &IpcNode,
    receiver: &mut impl BufRead,
    rate_hz: f64,
    samples: u64,
    shutdown: &Shutdown,
) -> Result<()> {
    expect_line(receiver, "ready")?;
    publish_phase::<RawImu>(node, &PHASES[0], receiver, rate_hz, samples, shutdown)?;
    publish_phase::<FusedImu>(node, &PHASES[1], receiver, rate_hz, samples, shutdown)?;
    publish_phase::<NavState>(node, &PHASES[2], receiver, rate_hz, samples, shutdown)?;
    Ok(())
}

pub fn expect_line(receiver: &mut impl BufRead, expected: &str) -> Result<()> {
    let mut line = String::new();
    receiver
        .read_line(&mut line)
        .context("reading the bench receiver")?;
    if line.trim() != expected {
        bail!("the bench receiver said {line:?}, expected {expected:?}");
    }
    Ok(())
}

fn publish_phase<T: Stamped + Default + std::fmt::Debug + ZeroCopySend + Copy + 'static>(
    node: &IpcNode,
    phase: &Phase,
    receiver: &mut impl BufRead,
    rate_hz: f64,
    samples: u64,
    shutdown: &Shutdown,
) -> Result<()> {
    let publisher = TopicPublisher::<T>::new(node, phase.topic)?;
    publish_paced(&publisher, rate_hz, 0..samples, false, shutdown)?;
    expect_line(receiver, &format!("done {}", phase.topic))
}

/// Publishes one sample per sequence number of `seqs` at `rate_hz`, paced like the block (sleep to
/// the tick, then send at once), each stamped as published by acquisition just before it is sent
/// (and as received, when `as_received`: the bare chain's source stands for the serial line too);
/// then the end of the phase, which the receivers' queues (sized for the block's rate) hold however
/// late they wake.
pub fn publish_paced<T: Stamped + Default + std::fmt::Debug + ZeroCopySend + Copy + 'static>(
    publisher: &TopicPublisher<T>,
    rate_hz: f64,
    seqs: impl Iterator<Item = u64>,
    as_received: bool,
    shutdown: &Shutdown,
) -> Result<()> {
    let period = Duration::from_secs_f64(1.0 / rate_hz);
    let mut next = Instant::now() + period;
    let mut sample = T::default();
    for seq in seqs {
        if shutdown.requested() {
            bail!("stopped");
        }
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        }
        next += period;
        let t = monotonic_ns();
        let header = sample.header_mut();
        header.origin_seq = seq;
        if as_received {
            header.origin_rx_ns = t;
        }
        header.stamp(Stage::Acquisition, t);
        publisher.publish(sample)?;
    }
    sample.header_mut().origin_seq = END_OF_PHASE;
    publisher.publish(sample)?;
    Ok(())
}
