//! `rins latency`: per-hop latency from the header stamps of the navigation and altitude topics;
//! optionally every sample's path as a Chrome trace and the hops as HDR interval logs.

mod hdr_log;
mod tail;
mod trace;

pub use tail::{TailRecorder, TailReport};

use std::io::{BufWriter, Write};
use std::path::Path;
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result, bail};
use hdrhistogram::Histogram;
use hdrhistogram::serialization::V2DeflateSerializer;
use ipc_types::{Altitude, Header, Stage, names};
use rins_navigator::lanes::NavSubscriber;
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serde::Serialize;

use crate::cli::LatencyArgs;
use hdr_log::IntervalLog;
use trace::TracedSample;

/// One measured hop: from one stamp to another, in nanoseconds; over the whole run and over the
/// current HDR log interval.
struct Hop {
    name: &'static str,
    histogram: Histogram<u64>,
    interval: Histogram<u64>,
}

impl Hop {
    fn new(name: &'static str) -> Result<Self> {
        let histogram = latency_histogram()?;
        Ok(Self {
            name,
            interval: histogram.clone(),
            histogram,
        })
    }

    fn record(&mut self, from_ns: u64, to_ns: u64) {
        if from_ns != 0 && to_ns >= from_ns {
            // Saturate rather than fail on an absurd value: it still shows up as the max.
            let ns = (to_ns - from_ns).max(1);
            self.histogram.saturating_record(ns);
            self.interval.saturating_record(ns);
        }
    }
}

/// Percentiles of one hop, µs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HopReport {
    /// Which hop.
    pub hop: &'static str,
    /// Samples measured.
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

/// The percentiles of `histogram` (ns) as hop `name`'s report.
pub fn report_of(name: &'static str, h: &Histogram<u64>) -> HopReport {
    let us = |ns: u64| ns as f64 / 1000.0;
    HopReport {
        hop: name,
        samples: h.len(),
        p50_us: us(h.value_at_quantile(0.5)),
        p99_us: us(h.value_at_quantile(0.99)),
        p999_us: us(h.value_at_quantile(0.999)),
        max_us: us(h.max()),
    }
}

fn report(hop: &Hop) -> HopReport {
    report_of(hop.name, &hop.histogram)
}

/// A histogram for latencies: 1 ns .. 10 s at 3 significant digits.
pub fn latency_histogram() -> Result<Histogram<u64>> {
    Ok(Histogram::new_with_bounds(1, 10_000_000_000, 3)?)
}

/// The hops of the pipeline, in path order, then the altimeter's.
pub const HOPS: [&str; 6] = [
    "serial rx -> acquisition published",
    "acquisition -> fusion published",
    "fusion -> navigator published",
    "serial rx -> nav state published",
    "navigator published -> consumer received",
    "acquisition -> altimeter published",
];
/// Index of the end-to-end hop in [`HOPS`].
pub const END_TO_END: usize = 3;

fn stage(h: &Header, s: Stage) -> u64 {
    h.stage_ns(s)
}

/// Opens an output file for the trace or the HDR log (refusing one already there unless
/// `overwrite`; a symbolic link is never followed).
fn create(path: &Path, overwrite: bool, what: &str) -> Result<BufWriter<std::fs::File>> {
    let file = rins_recording::create_file(path, overwrite).with_context(|| format!("--{what}"))?;
    Ok(BufWriter::new(file))
}

pub fn run(args: &LatencyArgs) -> Result<()> {
    let seconds = args.seconds;
    if !(seconds.is_finite() && seconds > 0.0) {
        bail!("--seconds {seconds}: must be a positive number");
    }
    if !(args.hdr_interval.is_finite() && args.hdr_interval >= 0.01) {
        bail!(
            "--hdr-interval {}: must be at least 0.01 s",
            args.hdr_interval
        );
    }
    // The output files first: a refused path costs no measurement.
    let mut trace_out = match &args.trace {
        Some(p) => Some((p, create(p, args.overwrite, "trace")?)),
        None => None,
    };
    let mut hdr_out = match &args.hdr {
        Some(p) => Some((p, create(p, args.overwrite, "hdr")?)),
        None => None,
    };
    let mut serializer = V2DeflateSerializer::new();
    let started = SystemTime::now();
    let mut hdr_log = match hdr_out.as_mut() {
        Some((_, out)) => Some(IntervalLog::begin(out, &mut serializer, started)?),
        None => None,
    };
    let interval = Duration::from_secs_f64(args.hdr_interval);
    let mut interval_start = started;
    // The samples the trace draws: a tool's buffer, sized for the block's rate.
    let mut traced: Vec<TracedSample> = if trace_out.is_some() {
        Vec::with_capacity(((seconds * 1000.0) as usize).min(10_000_000))
    } else {
        Vec::new()
    };

    let shutdown = Shutdown::install()?;
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("latency")?;
    let (node, settings) = (tool.node(), tool.settings());
    let mut hops = measure(
        node,
        Duration::from_secs_f64(seconds),
        &shutdown,
        |s, now| {
            if trace_out.is_some() {
                let h = &s.header;
                traced.push(TracedSample {
                    seq: h.origin_seq,
                    lane: s.lane,
                    rx_ns: h.origin_rx_ns,
                    acquisition_ns: stage(h, Stage::Acquisition),
                    fusion_ns: stage(h, Stage::Fusion),
                    navigator_ns: stage(h, Stage::Navigator),
                    consumer_ns: now,
                });
            }
        },
        |hops| {
            if let Some(log) = hdr_log.as_mut() {
                let now = SystemTime::now();
                if now.duration_since(interval_start).unwrap_or(Duration::ZERO) >= interval {
                    write_intervals(log, hops, interval_start, now)?;
                    interval_start = now;
                }
            }
            Ok(())
        },
    )?;
    if let Some(log) = hdr_log.as_mut() {
        write_intervals(log, &mut hops, interval_start, SystemTime::now())?;
    }
    drop(hdr_log);
    if let Some((path, mut out)) = hdr_out {
        out.flush()
            .with_context(|| format!("--hdr {}", path.display()))?;
    }
    if let Some((path, out)) = trace_out.as_mut() {
        serde_json::to_writer(&mut *out, &trace::build(&traced))
            .with_context(|| format!("--trace {}", path.display()))?;
        out.flush()
            .with_context(|| format!("--trace {}", path.display()))?;
    }
    if hops[END_TO_END].histogram.is_empty() {
        bail!(
            "no navigation state received in {seconds} s on prefix {:?}: is the pipeline running (rins up)?",
            settings.prefix
        );
    }
    let reports: Vec<HopReport> = hops.iter().map(report).collect();
    if args.json {
        println!("{}", serde_json::to_string(&reports)?);
    } else {
        println!(
            "{:<42} {:>8} {:>9} {:>9} {:>9} {:>9}",
            "hop", "samples", "p50 µs", "p99 µs", "p99.9 µs", "max µs"
        );
        for r in &reports {
            println!(
                "{:<42} {:>8} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
                r.hop, r.samples, r.p50_us, r.p99_us, r.p999_us, r.max_us
            );
        }
    }
    Ok(())
}

/// One interval of every hop that saw samples in it, then the intervals start over.
fn write_intervals<W: Write>(
    log: &mut IntervalLog<'_, W>,
    hops: &mut [Hop],
    from: SystemTime,
    to: SystemTime,
) -> Result<()> {
    for hop in hops.iter_mut() {
        if !hop.interval.is_empty() {
            log.interval(hop.name, &hop.interval, from, to)?;
        }
        hop.interval.reset();
    }
    Ok(())
}

/// How many of [`HOPS`] a navigation sample's stamps give (the altimeter's is the rest).
const PATH_HOPS: usize = 5;

/// The data path's hops of one navigation sample received at `now` (ns).
fn record_path(hops: &mut [Hop], s: &ipc_types::NavState, now: u64) {
    let h = &s.header;
    let (rx, acq, fus, navp) = (
        h.origin_rx_ns,
        stage(h, Stage::Acquisition),
        stage(h, Stage::Fusion),
        stage(h, Stage::Navigator),
    );
    hops[0].record(rx, acq);
    hops[1].record(acq, fus);
    hops[2].record(fus, navp);
    hops[3].record(rx, navp);
    hops[4].record(navp, now);
}

/// The data path's hops recorded sample by sample, for a measurement that reads the navigation
/// stream itself (the bench's bare chain): the same hops and names as the pipeline's.
pub struct PathHops {
    hops: [Hop; PATH_HOPS],
}

impl PathHops {
    pub fn new() -> Result<Self> {
        Ok(Self {
            hops: [
                Hop::new(HOPS[0])?,
                Hop::new(HOPS[1])?,
                Hop::new(HOPS[2])?,
                Hop::new(HOPS[3])?,
                Hop::new(HOPS[4])?,
            ],
        })
    }

    /// One navigation sample received at `now` (ns).
    pub fn record(&mut self, s: &ipc_types::NavState, now: u64) {
        record_path(&mut self.hops, s, now);
    }

    /// Every hop's percentiles, in [`HOPS`] order.
    pub fn reports(&self) -> Vec<HopReport> {
        self.hops.iter().map(report).collect()
    }
}

/// Measures the hops of the deployment `node` belongs to for `length` (or until `shutdown`):
/// the navigation stream consumers see (both lanes through the lane selector) and the altitude.
/// `on_nav` sees each navigation sample and its receive time; `on_turn` the hops after each
/// wake-up.
fn measure(
    node: &rins_runtime::ipc::IpcNode,
    length: Duration,
    shutdown: &Shutdown,
    mut on_nav: impl FnMut(&ipc_types::NavState, u64),
    mut on_turn: impl FnMut(&mut [Hop]) -> Result<()>,
) -> Result<[Hop; 6]> {
    let mut nav = NavSubscriber::new(node)?;
    let alt = TopicSubscriber::<Altitude>::new(node, names::ALTITUDE)?;
    let mut hops = [
        Hop::new(HOPS[0])?,
        Hop::new(HOPS[1])?,
        Hop::new(HOPS[2])?,
        Hop::new(HOPS[3])?,
        Hop::new(HOPS[4])?,
        Hop::new(HOPS[5])?,
    ];
    let end = Instant::now() + length;
    while Instant::now() < end && !shutdown.requested() {
        nav.wait(Duration::from_millis(50))?;
        while let Some(s) = nav.receive()? {
            let now = monotonic_ns();
            record_path(&mut hops[..PATH_HOPS], &s, now);
            on_nav(&s, now);
        }
        while let Some(a) = alt.receive()? {
            hops[5].record(
                stage(&a.header, Stage::Acquisition),
                stage(&a.header, Stage::Altimeter),
            );
        }
        on_turn(&mut hops)?;
    }
    Ok(hops)
}

/// The hops of the deployment `node` belongs to over `length`: what `rins bench ipc` compares
/// with the bare transport.
/// Every navigation sample is also given to `tail`.
pub fn measure_hops(
    node: &rins_runtime::ipc::IpcNode,
    length: Duration,
    shutdown: &Shutdown,
    tail: &mut TailRecorder,
) -> Result<Vec<HopReport>> {
    let hops = measure(node, length, shutdown, |s, _| tail.record(s), |_| Ok(()))?;
    Ok(hops.iter().map(report).collect())
}
