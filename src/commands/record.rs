//! `rins record FILE`: join a running deployment and write its topics to an MCAP file that
//! Foxglove opens and `rins replay` / `rins plot` read. The IPC loop only copies samples into a
//! bounded queue; a writer thread compresses and writes them, so a slow disk costs counted drops,
//! never a missed sample on the topics. A writer that fails (a full disk) ends the recording at
//! once: the report says why and how much was not recorded, and the command fails.
//!
//! `rins record --dir DIR` (and `rins up` with `[record] on_start`) writes numbered files there
//! instead, a new one whenever one reaches its size limit, the oldest of rins's own deleted to keep
//! the total (`rins::record`).

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{RawImu, names};
use rins::record::dir as record_dir;
use rins::record::rotation::{Limits, MB, RecordSink, Rotation};
use rins_recording::{ChannelId, RecordOptions, RecordSender, Recordable, Recorder};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicSubscriber};
use rins_runtime::payload::{Stamped, Versioned};
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;

use super::record_report::RecordReport;
use super::up_recording::check_target;

/// Samples queued between the IPC loop and the writer thread: a few seconds of every topic at
/// 1 kHz, enough to ride out a disk's stall.
const QUEUE: usize = 16_384;
/// The longest sleep waiting for a raw IMU sample: how often the other topics, the stop flag and
/// the progress line are served when the pipeline is quiet.
const WAIT: Duration = Duration::from_millis(10);
/// How often a rotating recording looks at its file's size: at 1 kHz, some 60 kB are written
/// meanwhile, well within the margin a file keeps below its limit.
const SIZE_CHECK: Duration = Duration::from_millis(100);

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

impl<T: Recordable + Versioned + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend> Tap
    for TypedTap<T>
{
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

fn tap<T: Recordable + Versioned + std::fmt::Debug + iceoryx2::prelude::ZeroCopySend>(
    time: fn(&T) -> Option<u64>,
) -> impl Fn(&IpcNode, &mut Recorder, &'static str) -> Result<Box<dyn Tap>> {
    move |node, recorder, topic| {
        let channel = recorder.channel_for::<T>(topic)?;
        let sub = TopicSubscriber::<T>::new(node, topic)?;
        Ok(Box::new(TypedTap { sub, channel, time }) as Box<dyn Tap>)
    }
}

fn stamped<T: Stamped>(s: &T) -> Option<u64> {
    Some(s.header().origin_rx_ns)
}

fn unstamped<T>(_: &T) -> Option<u64> {
    None
}

/// Every topic the topic table marks as recordable, with its place in the file.
macro_rules! record_choices {
    (@time stamped $payload:ident) => {
        stamped::<ipc_types::$payload>
    };
    (@time unstamped $payload:ident) => {
        unstamped::<ipc_types::$payload>
    };
    ($($rank:literal $short:literal $constant:ident $payload:ident $kind:ident;)+) => {
        [$(
            (
                $rank,
                TopicChoice {
                    short: $short,
                    topic: names::$constant,
                    tap: |node, recorder, topic| {
                        tap::<ipc_types::$payload>(record_choices!(@time $kind $payload))(
                            node, recorder, topic,
                        )
                    },
                },
            ),
        )+]
    };
}

/// Every topic a recording can hold, in the order they are written to the file.
fn all_choices() -> Vec<TopicChoice> {
    let mut ranked = ipc_types::for_each_topic!(record => record_choices);
    ranked.sort_by_key(|(rank, _)| *rank);
    ranked.into_iter().map(|(_, choice)| choice).collect()
}

/// The short names `--topics` accepts.
pub fn topic_names() -> Vec<&'static str> {
    all_choices().iter().map(|c| c.short).collect()
}

/// Where a recording goes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// One file.
    File(PathBuf),
    /// Numbered files in a directory, within its limits.
    Dir(Limits),
}

impl Target {
    /// The file, or the directory.
    pub fn path(&self) -> &Path {
        match self {
            Self::File(f) => f,
            Self::Dir(l) => &l.dir,
        }
    }

    /// The recording `rins up` makes: `--record FILE`, else `[record]` when `on_start` (in
    /// `state_directory`, systemd's `$STATE_DIRECTORY`, unless `dir` names one) and the raw
    /// samples come from the device, not from a replay (`external_source`), else none.
    pub fn for_up(
        record: Option<&Path>,
        cfg: &rins::record::config::RecordConfig,
        state_directory: Option<&str>,
        external_source: bool,
    ) -> Option<Self> {
        match record {
            Some(file) => Some(Self::File(file.to_path_buf())),
            None if cfg.on_start && !external_source => Some(Self::Dir(Limits {
                dir: cfg.directory(state_directory),
                max_file_bytes: cfg.max_file_mb * MB,
                max_total_bytes: cfg.max_total_mb * MB,
            })),
            None => None,
        }
    }

    /// Checks, before anything starts, that the recording can be made: see [`check_target`] for
    /// a file; a directory is created when missing and refused when unsafe (`record.dir`).
    pub fn check(&self) -> Result<()> {
        match self {
            Self::File(f) => check_target(f),
            Self::Dir(l) => record_dir::prepare(&l.dir, "record.dir"),
        }
    }

    /// The arguments of `rins record` that make this recording.
    pub fn record_args(&self) -> Vec<std::ffi::OsString> {
        match self {
            Self::File(f) => vec![f.into(), "--overwrite".into()],
            Self::Dir(l) => vec![
                "--dir".into(),
                l.dir.clone().into(),
                "--max-file-mb".into(),
                (l.max_file_bytes / MB).to_string().into(),
                "--max-total-mb".into(),
                (l.max_total_bytes / MB).to_string().into(),
            ],
        }
    }
}

/// What to record and for how long.
pub struct RecordRequest<'a> {
    /// The MCAP file, or the directory of a rotating recording.
    pub target: &'a Target,
    /// Short topic names; empty: every topic.
    pub topics: &'a [String],
    /// Stop after this many seconds; none: until SIGINT/SIGTERM.
    pub duration_s: Option<f64>,
    /// Replace an existing file (one file only: a rotating recording never replaces one).
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
    let (recorder, rotation) = match req.target {
        Target::File(file) => {
            let options = RecordOptions {
                overwrite: req.overwrite,
                ..RecordOptions::default()
            };
            (Recorder::create(file, &options)?, None)
        }
        Target::Dir(limits) => {
            record_dir::prepare(&limits.dir, "--dir")?;
            let mut rotation = Rotation::new(limits.clone())?;
            (rotation.create_next(&[])?, Some(rotation))
        }
    };
    let mut recorder = recorder;
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
    let mut sink = RecordSink::start(recorder, rotation, QUEUE)?;
    if let Some(ready) = req.ready_file {
        std::fs::write(ready, b"").with_context(|| format!("cannot create {}", ready.display()))?;
    }
    let started = Instant::now();
    let end = req.duration_s.map(|d| started + Duration::from_secs_f64(d));
    let mut received = 0u64;
    let mut next_progress = started + Duration::from_secs(1);
    let mut next_size_check = started + SIZE_CHECK;
    while !shutdown.requested() && end.is_none_or(|e| Instant::now() < e) {
        // Once the writer failed, the samples that arrive are still taken off the topics and
        // counted as not recorded until the run ends.
        if let Some(why) = sink.newly_failed() {
            eprintln!(
                "recording {} failed, nothing more is recorded: {why}",
                sink.path().display()
            );
        }
        match &wake {
            Some(w) => {
                w.wait(WAIT)?;
                while w.receive()?.is_some() {}
            }
            None => std::thread::sleep(Duration::from_millis(1)),
        }
        let now = monotonic_ns();
        for (_, tap) in &mut taps {
            received += tap.drain(sink.sender(), now)?;
        }
        if Instant::now() >= next_size_check {
            next_size_check += SIZE_CHECK;
            // Between two drains: every sample taken off the topics goes to one file or the next.
            if let Some(next) = sink.rotate_if_full()
                && req.progress
            {
                eprintln!("recording on in {}", next.display());
            }
            sink.collect_closed();
        }
        if req.progress && Instant::now() >= next_progress {
            next_progress += Duration::from_secs(1);
            eprintln!(
                "recording {}: {:.0} s, {received} samples, {} dropped",
                sink.path().display(),
                started.elapsed().as_secs_f64(),
                sink.dropped_total()
            );
        }
    }
    // What arrived while stopping is written too.
    let now = monotonic_ns();
    for (_, tap) in &mut taps {
        received += tap.drain(sink.sender(), now)?;
    }
    let seconds = started.elapsed().as_secs_f64();
    let outcome = sink.finish();
    drop(taps);
    drop(wake);
    drop(tool);
    let rotating = matches!(req.target, Target::Dir(_));
    Ok(RecordReport::new(
        req.target.path(),
        rotating,
        outcome,
        received,
        seconds,
    ))
}

/// `rins record`: records until Ctrl-C or `--duration`, then prints what was written.
pub fn run(args: &crate::cli::RecordArgs) -> Result<()> {
    let shutdown = Shutdown::install()?;
    let target = match (&args.file, &args.dir) {
        (Some(file), _) if args.max_file_mb.is_some() || args.max_total_mb.is_some() => bail!(
            "--max-file-mb and --max-total-mb apply to --dir: {} is one file",
            file.display()
        ),
        (Some(file), _) => Target::File(file.clone()),
        (None, Some(dir)) => {
            let defaults = rins::record::config::RecordConfig::default();
            let max_file_mb = args.max_file_mb.unwrap_or(defaults.max_file_mb);
            let max_total_mb = args.max_total_mb.unwrap_or(defaults.max_total_mb);
            rins::record::config::check_limits(max_file_mb, max_total_mb, "--")
                .map_err(anyhow::Error::msg)?;
            Target::Dir(Limits {
                dir: dir.clone(),
                max_file_bytes: max_file_mb * MB,
                max_total_bytes: max_total_mb * MB,
            })
        }
        (None, None) => bail!("name the FILE to record into, or --dir"),
    };
    let report = record(
        &RecordRequest {
            target: &target,
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
    if let Some(error) = &report.error {
        bail!(
            "recording {} failed ({} samples not recorded): {error}",
            report.file,
            report.samples_not_recorded
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The record entries of the topic table: rank, short name, topic.
    macro_rules! record_entries {
        ($($rank:literal $short:literal $constant:ident $payload:ident $kind:ident;)+) => {
            [$(($rank, $short, names::$constant)),+]
        };
    }

    #[test]
    fn the_choices_are_in_the_order_a_recording_writes_its_channels() {
        let table = ipc_types::for_each_topic!(record => record_entries);
        let choices = all_choices();
        assert_eq!(choices.len(), table.len());
        // Each rank from 0 is given once, so the order of the channels is the table's ranks.
        for (rank, choice) in choices.iter().enumerate() {
            let entries: Vec<_> = table.iter().filter(|(r, ..)| *r == rank).collect();
            assert_eq!(entries.len(), 1, "rank {rank}: {entries:?}");
            let (_, short, topic) = entries[0];
            assert_eq!(
                (choice.short, choice.topic),
                (*short, *topic),
                "rank {rank}"
            );
        }
        // Recordings have always begun with the raw sensors and held the standby lane and the
        // health report at these places.
        assert_eq!(
            topic_names()[..4],
            ["raw-imu", "raw-baro", "raw-mag", "raw-aux"]
        );
        assert_eq!(choices[7].topic, names::NAV_LANES[1]);
        assert_eq!(choices[9].topic, names::HEALTH);
    }

    #[test]
    fn up_records_its_file_else_the_configured_directory_but_not_a_replay() {
        let mut cfg = rins::record::config::RecordConfig::default();
        let file = Path::new("/tmp/f.mcap");
        assert_eq!(
            Target::for_up(None, &cfg, Some("/var/lib/rins"), false),
            None
        );
        cfg.on_start = true;
        assert_eq!(
            Target::for_up(Some(file), &cfg, Some("/var/lib/rins"), false),
            Some(Target::File(file.into()))
        );
        let dir = Target::for_up(None, &cfg, Some("/var/lib/rins"), false).expect("a target");
        assert_eq!(
            dir,
            Target::Dir(Limits {
                dir: "/var/lib/rins".into(),
                max_file_bytes: 256_000_000,
                max_total_bytes: 2_048_000_000,
            })
        );
        let args: Vec<String> = dir
            .record_args()
            .iter()
            .map(|a| a.to_string_lossy().into_owned())
            .collect();
        assert_eq!(
            args,
            [
                "--dir",
                "/var/lib/rins",
                "--max-file-mb",
                "256",
                "--max-total-mb",
                "2048"
            ]
        );
        // A replay's deployment feeds recorded samples: no flight to record.
        assert_eq!(
            Target::for_up(None, &cfg, Some("/var/lib/rins"), true),
            None
        );
    }
}
