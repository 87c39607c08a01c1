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
use ipc_types::{
    Altitude, FaultApplied, FusedImu, FusionControl, FusionReply, Health, HealthReport, NavState,
    RawAux, RawBaro, RawImu, RawMag, SimControl, Truth, names,
};
use rins::record::dir as record_dir;
use rins::record::rotation::{FileOutcome, Limits, MB, RecordSink, Rotation, error_text};
use rins_recording::{ChannelId, RecordOptions, RecordSender, Recordable, Recorder};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicSubscriber};
use rins_runtime::payload::Stamped;
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serde::{Deserialize, Serialize};

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
#[derive(Debug, Serialize, Deserialize)]
pub struct RecordReport {
    /// The file written; with `--dir`, the directory.
    pub file: String,
    /// Samples written, all topics.
    pub samples_written: u64,
    /// Samples dropped because the writer could not keep up.
    pub samples_dropped: u64,
    /// Samples received from the topics.
    pub samples_received: u64,
    /// Samples received that are not in the file: dropped, or queued when the writer failed.
    #[serde(default)]
    pub samples_not_recorded: u64,
    /// Why the recording failed (the file is incomplete); absent when it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// How long the recording ran, s.
    pub seconds: f64,
    /// Size of the file, bytes; with `--dir`, of every file written.
    pub file_bytes: u64,
    /// Per topic: written and dropped.
    pub topics: Vec<TopicCount>,
    /// With `--dir`: each file written, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<FileCount>,
    /// With `--dir`: the older recordings deleted to keep the total.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files_deleted: Vec<String>,
}

/// One file of a recording made with `--dir`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileCount {
    /// The file.
    pub file: String,
    /// Samples written to it.
    pub samples_written: u64,
    /// Its size, bytes.
    pub file_bytes: u64,
}

/// One topic of [`RecordReport`].
#[derive(Debug, Serialize, Deserialize)]
pub struct TopicCount {
    /// The topic.
    pub topic: String,
    /// Samples written.
    pub written: u64,
    /// Samples dropped.
    pub dropped: u64,
}

impl RecordReport {
    /// The report of the files of `target`, `received` samples taken off the topics in `seconds`.
    fn new(
        target: &Target,
        (files, deleted, problems): (Vec<FileOutcome>, Vec<PathBuf>, Vec<String>),
        received: u64,
        seconds: f64,
    ) -> Self {
        let written: u64 = files.iter().map(|f| f.written).sum();
        let mut topics: Vec<TopicCount> = Vec::new();
        for (topic, w, d) in files.iter().flat_map(|f| f.topics.iter()) {
            match topics.iter_mut().find(|t| t.topic == *topic) {
                Some(t) => {
                    t.written += w;
                    t.dropped += d;
                }
                None => topics.push(TopicCount {
                    topic: topic.clone(),
                    written: *w,
                    dropped: *d,
                }),
            }
        }
        // The first failure of a file, then what kept the rotation from its limits.
        let error = files
            .iter()
            .find_map(|f| f.error.as_ref().map(|e| error_text(e)))
            .or_else(|| (!problems.is_empty()).then(|| problems.join("; ")));
        let rotating = matches!(target, Target::Dir(_));
        Self {
            file: target.path().display().to_string(),
            samples_written: written,
            samples_dropped: files.iter().map(|f| f.dropped).sum(),
            samples_received: received,
            samples_not_recorded: received.saturating_sub(written),
            error,
            seconds,
            file_bytes: files.iter().map(|f| f.file_bytes).sum(),
            topics,
            files: if rotating {
                files
                    .iter()
                    .map(|f| FileCount {
                        file: f.path.display().to_string(),
                        samples_written: f.written,
                        file_bytes: f.file_bytes,
                    })
                    .collect()
            } else {
                Vec::new()
            },
            files_deleted: deleted.iter().map(|p| p.display().to_string()).collect(),
        }
    }
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
    Ok(RecordReport::new(req.target, outcome, received, seconds))
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

/// What `rins up --record` reports of its recording in the run summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordingOutcome {
    /// The file.
    pub file: String,
    /// Samples written, all topics.
    pub samples_written: u64,
    /// Samples dropped because the writer could not keep up, or had stopped.
    pub samples_dropped: u64,
    /// Samples received that are not in the file.
    pub samples_not_recorded: u64,
    /// Size of the file, bytes (of every file, in a directory).
    pub file_bytes: u64,
    /// Why the recording failed (a write error, the recorder stopping); `null` when it did not.
    pub error: Option<String>,
    /// In a directory (`[record]`): each file written, in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<FileCount>,
    /// In a directory: the older recordings deleted to keep the total.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub files_deleted: Vec<String>,
}

impl RecordingOutcome {
    /// From how the recorder of `file` ended and what it printed on stdout (its `--json` report
    /// last): a recorder that failed, or ended without a report, is an error of the recording.
    pub fn from_recorder(file: &Path, status: std::process::ExitStatus, stdout: &[u8]) -> Self {
        let text = String::from_utf8_lossy(stdout);
        let report = text
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .and_then(|l| serde_json::from_str::<RecordReport>(l).ok());
        match report {
            Some(r) => Self {
                error: r.error.or_else(|| {
                    (!status.success()).then(|| format!("the recorder ended with {status}"))
                }),
                file: r.file,
                samples_written: r.samples_written,
                samples_dropped: r.samples_dropped,
                samples_not_recorded: r.samples_not_recorded,
                file_bytes: r.file_bytes,
                files: r.files,
                files_deleted: r.files_deleted,
            },
            None => Self::lost(
                file,
                format!("the recorder ended ({status}) without a report"),
            ),
        }
    }

    /// A recording of `file` that ended with `error` and nothing known of what it wrote.
    pub fn lost(file: &Path, error: String) -> Self {
        Self {
            file: file.display().to_string(),
            samples_written: 0,
            samples_dropped: 0,
            samples_not_recorded: 0,
            file_bytes: std::fs::metadata(file).map_or(0, |m| m.len()),
            error: Some(error),
            files: Vec::new(),
            files_deleted: Vec::new(),
        }
    }

    /// Why the run failed to record what was asked: an error, or samples that are not in the
    /// file. `None` when the file holds every sample received.
    pub fn failure(&self) -> Option<String> {
        match &self.error {
            Some(e) => Some(format!(
                "recording {} failed ({} samples not recorded): {e}",
                self.file, self.samples_not_recorded
            )),
            None if self.samples_not_recorded > 0 => Some(format!(
                "recording {}: {} samples not recorded (the writer could not keep up)",
                self.file, self.samples_not_recorded
            )),
            None => None,
        }
    }

    /// One line of the text summary.
    pub fn text(&self) -> String {
        let mut head = format!(
            "  recording {}: {} samples written, {} dropped, {} bytes",
            self.file, self.samples_written, self.samples_dropped, self.file_bytes
        );
        if !self.files.is_empty() {
            head.push_str(&format!(
                " in {} files, {} older deleted",
                self.files.len(),
                self.files_deleted.len()
            ));
        }
        match self.failure() {
            Some(why) => format!("{head}\n  FAILED: {why}\n"),
            None => format!("{head}\n"),
        }
    }
}

/// Checks, before anything starts, that a recording can be made at `path`: an existing target
/// must be a regular file (or a symbolic link, which is replaced, never followed), and its
/// directory must let a file be created there. Errors name the path and the system's reason.
pub fn check_target(path: &Path) -> Result<()> {
    use std::os::unix::fs::FileTypeExt;
    match std::fs::symlink_metadata(path) {
        Ok(meta) => {
            let t = meta.file_type();
            let kind = if t.is_dir() {
                Some("a directory")
            } else if t.is_fifo() {
                Some("a FIFO")
            } else if t.is_socket() {
                Some("a socket")
            } else if t.is_char_device() || t.is_block_device() {
                Some("a device")
            } else {
                None
            };
            if let Some(kind) = kind {
                bail!(
                    "--record {}: it is {kind}, not a regular file; refusing to record there",
                    path.display()
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => bail!("--record {}: {e}", path.display()),
    }
    let Some(name) = path.file_name() else {
        bail!("--record {}: names no file", path.display());
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // A file of our own beside the target, so that an existing recording is not touched before
    // the run starts.
    let mut probe_name = std::ffi::OsString::from(".");
    probe_name.push(name);
    probe_name.push(format!(".{}.probe", std::process::id()));
    let probe = dir.join(probe_name);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .with_context(|| format!("--record {}: cannot create it", path.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Waits until the recorder started for `file` has created `ready` (it then has subscribed to
/// every topic); `Ok(false)` when a stop was requested meanwhile. Fails as soon as the recorder
/// exits (its own error is on stderr already), or after `limit`.
pub fn wait_until_ready(
    child: &mut std::process::Child,
    ready: &Path,
    file: &Path,
    shutdown: &Shutdown,
    limit: Duration,
) -> Result<bool> {
    let deadline = Instant::now() + limit;
    while !ready.exists() {
        if shutdown.requested() {
            return Ok(false);
        }
        if let Some(status) = child.try_wait()? {
            bail!(
                "the recorder of {} ended ({status}) before it started",
                file.display()
            );
        }
        if Instant::now() >= deadline {
            bail!(
                "the recorder of {} did not start within {limit:?}",
                file.display()
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(true)
}

/// The run summary of `rins up --json`, with its recording when there was one.
pub fn summary_json(
    summary: &rins_watchdog::summary::Summary,
    recording: Option<&RecordingOutcome>,
) -> Result<String> {
    #[derive(Serialize)]
    struct WithRecording<'a> {
        #[serde(flatten)]
        summary: &'a rins_watchdog::summary::Summary,
        #[serde(skip_serializing_if = "Option::is_none")]
        recording: Option<&'a RecordingOutcome>,
    }
    Ok(serde_json::to_string(&WithRecording {
        summary,
        recording,
    })?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;

    fn status(code: i32) -> std::process::ExitStatus {
        std::process::ExitStatus::from_raw(code << 8)
    }

    #[test]
    fn a_recorder_that_hit_a_full_disk_fails_the_run_and_says_why() {
        let report = RecordReport {
            file: "/tmp/x.mcap".into(),
            samples_written: 1_200,
            samples_dropped: 300,
            samples_received: 9_000,
            samples_not_recorded: 7_800,
            error: Some("/tmp/x.mcap: writing MCAP: No space left on device (os error 28)".into()),
            seconds: 3.0,
            file_bytes: 262_144,
            topics: Vec::new(),
            files: Vec::new(),
            files_deleted: Vec::new(),
        };
        let stdout = format!("{}\n", serde_json::to_string(&report).unwrap());
        let r =
            RecordingOutcome::from_recorder(Path::new("/tmp/x.mcap"), status(1), stdout.as_bytes());
        let why = r.failure().expect("a failure");
        assert!(why.contains("No space left on device"), "{why}");
        assert!(why.contains("7800 samples not recorded"), "{why}");
        assert!(r.text().contains("FAILED"), "{}", r.text());
        let json = summary_json(&rins_watchdog::summary::Summary::default(), Some(&r)).unwrap();
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["recording"]["samples_not_recorded"], 7_800);
        assert!(
            v["recording"]["error"]
                .as_str()
                .unwrap()
                .contains("os error 28")
        );
        // The summary's own fields are still at the top.
        assert_eq!(v["frames"], 0);
    }

    #[test]
    fn a_recorder_without_a_report_or_with_drops_fails_the_run() {
        let r = RecordingOutcome::from_recorder(Path::new("/tmp/none.mcap"), status(1), b"");
        assert!(r.failure().unwrap().contains("without a report"));
        let report = RecordReport {
            file: "/tmp/y.mcap".into(),
            samples_written: 10,
            samples_dropped: 2,
            samples_received: 12,
            samples_not_recorded: 2,
            error: None,
            seconds: 1.0,
            file_bytes: 100,
            topics: Vec::new(),
            files: Vec::new(),
            files_deleted: Vec::new(),
        };
        let stdout = serde_json::to_string(&report).unwrap();
        let r =
            RecordingOutcome::from_recorder(Path::new("/tmp/y.mcap"), status(0), stdout.as_bytes());
        assert!(r.failure().unwrap().contains("2 samples not recorded"));
        let whole = RecordReport {
            samples_dropped: 0,
            samples_not_recorded: 0,
            ..report
        };
        let stdout = serde_json::to_string(&whole).unwrap();
        let r =
            RecordingOutcome::from_recorder(Path::new("/tmp/y.mcap"), status(0), stdout.as_bytes());
        assert_eq!(r.failure(), None);
        let json = summary_json(&rins_watchdog::summary::Summary::default(), None).unwrap();
        assert!(!json.contains("recording"), "{json}");
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

    #[test]
    fn a_target_that_is_no_regular_file_or_cannot_be_created_is_refused() {
        let dir = std::env::temp_dir().join(format!("rins-record-target-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let e = check_target(&dir).unwrap_err().to_string();
        assert!(
            e.contains("a directory") && e.contains(&dir.display().to_string()),
            "{e}"
        );
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = check_target(&fifo).unwrap_err().to_string();
        assert!(e.contains("a FIFO"), "{e}");
        let e = format!("{:#}", check_target(Path::new("/dev/null")).unwrap_err());
        assert!(e.contains("a device"), "{e}");
        let e = format!(
            "{:#}",
            check_target(&dir.join("no/such/dir/x.mcap")).unwrap_err()
        );
        assert!(
            e.contains("no/such/dir/x.mcap") && e.contains("No such file"),
            "{e}"
        );
        // A path that can be created passes, and nothing is left behind.
        check_target(&dir.join("ok.mcap")).unwrap();
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("fifo")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
