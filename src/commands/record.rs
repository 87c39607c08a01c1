//! `rins record FILE`: join a running deployment and write its topics to an MCAP file that
//! Foxglove opens and `rins replay` / `rins plot` read. The IPC loop only copies samples into a
//! bounded queue; a writer thread compresses and writes them, so a slow disk costs counted drops,
//! never a missed sample on the topics.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{
    Altitude, FaultApplied, FusedImu, FusionControl, FusionReply, Health, HealthReport, NavState,
    RawAux, RawBaro, RawImu, RawMag, SimControl, Truth, names,
};
use rins_recording::{
    ChannelId, RecordOptions, RecordSender, RecordSummary, Recordable, Recorder, join_writer,
    spawn_writer,
};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicSubscriber};
use rins_runtime::payload::Stamped;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serde::Serialize;

/// Samples queued between the IPC loop and the writer thread: a few seconds of every topic at
/// 1 kHz, enough to ride out a disk's stall.
const QUEUE: usize = 16_384;
/// The longest sleep waiting for a raw IMU sample: how often the other topics, the stop flag and
/// the progress line are served when the pipeline is quiet.
const WAIT: Duration = Duration::from_millis(10);

/// One subscribed topic feeding the writer.
trait Tap {
    /// Queues every sample received since the last call; the number received.
    fn drain(&mut self, out: &RecordSender, now_ns: u64) -> Result<u64>;
}

/// A topic of payload `T`, written to `channel` with its measurement time as log time.
struct TypedTap<T: Recordable + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend> {
    sub: TopicSubscriber<T>,
    channel: ChannelId,
    /// The measurement time of a sample (the serial receive time of its frame), if it has one.
    time: fn(&T) -> Option<u64>,
}

impl<T: Recordable + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend> Tap for TypedTap<T> {
    fn drain(&mut self, out: &RecordSender, now_ns: u64) -> Result<u64> {
        let mut n = 0;
        while let Some(s) = self.sub.receive()? {
            n += 1;
            let log_time = (self.time)(&s).filter(|t| *t > 0).unwrap_or(now_ns);
            // A full queue is counted by the sender; the summary reports it.
            let _ = out.try_send_payload(self.channel, log_time, now_ns, &s);
        }
        Ok(n)
    }
}

/// The topic `rins record --topics` accepts by short name, with its full name and how to tap it.
struct TopicChoice {
    short: &'static str,
    topic: &'static str,
    tap: fn(&IpcNode, &mut Recorder, &'static str) -> Result<Box<dyn Tap>>,
}

fn tap<T: Recordable + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend>(
    time: fn(&T) -> Option<u64>,
) -> impl Fn(&IpcNode, &mut Recorder, &'static str) -> Result<Box<dyn Tap>> {
    move |node, recorder, topic| {
        let channel = recorder.channel_for::<T>(topic)?;
        let sub = TopicSubscriber::<T>::new(node, topic)?;
        Ok(Box::new(TypedTap { sub, channel, time }) as Box<dyn Tap>)
    }
}

macro_rules! choices {
    ($(($short:literal, $topic:expr, $ty:ty, $time:expr)),* $(,)?) => {
        [$(TopicChoice {
            short: $short,
            topic: $topic,
            tap: |node, recorder, topic| tap::<$ty>($time)(node, recorder, topic),
        }),*]
    };
}

fn stamped<T: Stamped>(s: &T) -> Option<u64> {
    Some(s.header().origin_rx_ns)
}

fn unstamped<T>(_: &T) -> Option<u64> {
    None
}

/// Every topic a recording can hold, in the order they are written to the file.
fn all_choices() -> [TopicChoice; 15] {
    choices![
        ("raw-imu", names::RAW_IMU, RawImu, stamped::<RawImu>),
        ("raw-baro", names::RAW_BARO, RawBaro, stamped::<RawBaro>),
        ("raw-mag", names::RAW_MAG, RawMag, stamped::<RawMag>),
        ("raw-aux", names::RAW_AUX, RawAux, stamped::<RawAux>),
        ("fused-imu", names::FUSED_IMU, FusedImu, stamped::<FusedImu>),
        ("altitude", names::ALTITUDE, Altitude, stamped::<Altitude>),
        ("nav", names::NAV_LANES[0], NavState, stamped::<NavState>),
        (
            "nav-standby",
            names::NAV_LANES[1],
            NavState,
            stamped::<NavState>
        ),
        ("truth", names::TRUTH, Truth, stamped::<Truth>),
        (
            "health",
            names::HEALTH,
            HealthReport,
            unstamped::<HealthReport>
        ),
        ("heartbeat", names::HEARTBEAT, Health, unstamped::<Health>),
        (
            "fault",
            names::SIM_FAULT_APPLIED,
            FaultApplied,
            unstamped::<FaultApplied>
        ),
        (
            "sim-control",
            names::SIM_CONTROL,
            SimControl,
            unstamped::<SimControl>
        ),
        (
            "fusion-control",
            names::FUSION_CONTROL,
            FusionControl,
            unstamped::<FusionControl>
        ),
        (
            "fusion-reply",
            names::FUSION_REPLY,
            FusionReply,
            unstamped::<FusionReply>
        ),
    ]
}

/// The short names `--topics` accepts.
pub fn topic_names() -> Vec<&'static str> {
    all_choices().iter().map(|c| c.short).collect()
}

/// What `rins record --json` prints last.
#[derive(Debug, Serialize)]
pub struct RecordReport {
    /// The file written.
    pub file: String,
    /// Samples written, all topics.
    pub samples_written: u64,
    /// Samples dropped because the writer could not keep up.
    pub samples_dropped: u64,
    /// Samples received from the topics.
    pub samples_received: u64,
    /// How long the recording ran, s.
    pub seconds: f64,
    /// Size of the file, bytes.
    pub file_bytes: u64,
    /// Per topic: written and dropped.
    pub topics: Vec<TopicCount>,
}

/// One topic of [`RecordReport`].
#[derive(Debug, Serialize)]
pub struct TopicCount {
    /// The topic.
    pub topic: String,
    /// Samples written.
    pub written: u64,
    /// Samples dropped.
    pub dropped: u64,
}

impl RecordReport {
    fn new(summary: &RecordSummary, received: u64, seconds: f64) -> Self {
        Self {
            file: summary.path.display().to_string(),
            samples_written: summary.samples_written,
            samples_dropped: summary.samples_dropped,
            samples_received: received,
            seconds,
            file_bytes: summary.file_bytes,
            topics: summary
                .topics
                .iter()
                .map(|t| TopicCount {
                    topic: t.topic.clone(),
                    written: t.written,
                    dropped: t.dropped,
                })
                .collect(),
        }
    }
}

/// What to record and for how long.
pub struct RecordRequest<'a> {
    /// The MCAP file.
    pub file: &'a Path,
    /// Short topic names; empty: every topic.
    pub topics: &'a [String],
    /// Stop after this many seconds; none: until SIGINT/SIGTERM.
    pub duration_s: Option<f64>,
    /// Replace an existing file.
    pub overwrite: bool,
    /// Print a progress line to stderr each second.
    pub progress: bool,
    /// Created once every topic is subscribed: from then on nothing published is missed.
    pub ready_file: Option<&'a Path>,
}

/// Records until stopped (signal or duration) and returns what was written.
pub fn record(req: &RecordRequest<'_>, shutdown: &Shutdown) -> Result<RecordReport> {
    if let Some(d) = req.duration_s
        && !(d.is_finite() && d > 0.0)
    {
        bail!("--duration {d}: must be a positive number of seconds");
    }
    let choices = all_choices();
    for t in req.topics {
        if !choices.iter().any(|c| c.short == t) {
            bail!(
                "--topics: unknown topic {t:?}; known: {}",
                topic_names().join(", ")
            );
        }
    }
    let tool = ToolNode::join("record")?;
    let options = RecordOptions {
        overwrite: req.overwrite,
        ..RecordOptions::default()
    };
    let mut recorder = Recorder::create(req.file, &options)?;
    let mut taps = Vec::new();
    let mut imu_index = None;
    for c in &choices {
        if req.topics.is_empty() || req.topics.iter().any(|t| t == c.short) {
            if c.topic == names::RAW_IMU {
                imu_index = Some(taps.len());
            }
            taps.push((c.topic, (c.tap)(tool.node(), &mut recorder, c.topic)?));
        }
    }
    // Woken by the raw IMU, the fastest topic, when it is recorded; by the clock otherwise.
    let wake = match imu_index {
        Some(_) => Some(TopicSubscriber::<RawImu>::new(tool.node(), names::RAW_IMU)?),
        None => None,
    };
    let (sender, writer) = spawn_writer(recorder, QUEUE).context("cannot start the writer")?;
    if let Some(ready) = req.ready_file {
        std::fs::write(ready, b"").with_context(|| format!("cannot create {}", ready.display()))?;
    }
    let started = Instant::now();
    let end = req.duration_s.map(|d| started + Duration::from_secs_f64(d));
    let mut received = 0u64;
    let mut next_progress = started + Duration::from_secs(1);
    while !shutdown.requested() && end.is_none_or(|e| Instant::now() < e) {
        match &wake {
            Some(w) => {
                w.wait(WAIT)?;
                while w.receive()?.is_some() {}
            }
            None => std::thread::sleep(Duration::from_millis(1)),
        }
        let now = monotonic_ns();
        for (_, tap) in &mut taps {
            received += tap.drain(&sender, now)?;
        }
        if req.progress && Instant::now() >= next_progress {
            next_progress += Duration::from_secs(1);
            eprintln!(
                "recording {}: {:.0} s, {received} samples, {} dropped",
                req.file.display(),
                started.elapsed().as_secs_f64(),
                sender.dropped_total()
            );
        }
    }
    // What arrived while stopping is written too.
    let now = monotonic_ns();
    for (_, tap) in &mut taps {
        received += tap.drain(&sender, now)?;
    }
    let seconds = started.elapsed().as_secs_f64();
    drop(sender);
    let summary = join_writer(writer)?;
    drop(taps);
    drop(wake);
    drop(tool);
    Ok(RecordReport::new(&summary, received, seconds))
}

/// `rins record`: records until Ctrl-C or `--duration`, then prints what was written.
pub fn run(args: &crate::cli::RecordArgs) -> Result<()> {
    let shutdown = Shutdown::install()?;
    let report = record(
        &RecordRequest {
            file: &args.file,
            topics: &args.topics,
            duration_s: args.duration,
            overwrite: args.overwrite,
            progress: !args.json,
            ready_file: args.ready_file.as_deref(),
        },
        &shutdown,
    )?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "{}: {} samples written, {} dropped, {} bytes in {:.1} s",
            report.file,
            report.samples_written,
            report.samples_dropped,
            report.file_bytes,
            report.seconds
        );
    }
    Ok(())
}
