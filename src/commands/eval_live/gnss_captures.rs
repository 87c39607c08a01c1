//! `rins eval gnss-captures --live`: each capture's receiver bytes written at line pace through a
//! pseudo-terminal to a running `rins service gnss` (a private IPC root and prefix per capture),
//! the fixes and line reports it publishes collected, and the fixes scored exactly as the
//! in-process decoder's ([`rins_eval::gnss_captures::live`]). Several captures run at once, each
//! with its own terminal, process and prefix.

use std::fs::File;
use std::io::Write;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{GnssFix, GnssLinkReport, Health, ServiceKind, names};
use rins::replay::live::private_settings;
use rins_eval::gnss_captures::live::{
    LiveCapture, LiveCapturesReport, LiveFeed, build_live, evaluate_live,
};
use rins_eval::gnss_captures::replay::{CHUNK_BYTES, receiver_bytes};
use rins_eval::gnss_captures::{CaptureResult, Failure, capture_names, read_capture};
use rins_runtime::ipc::{IpcSettings, PREFIX_ENV, ROOT_ENV, TopicSubscriber};
use rins_runtime::shutdown::Shutdown;
use rins_runtime::tool_node::ToolNode;
use serialport::{SerialPort, TTYPort};

use crate::commands::progress::Progress;

/// How long the service may take to start and beat.
const START_TIMEOUT: Duration = Duration::from_secs(30);
/// Silence after the last byte before the service is stopped: the decoder closes an NMEA epoch
/// after 1 s without a byte, and the service reads with a 50 ms timeout.
const QUIET: Duration = Duration::from_millis(1_500);
/// How long the service may take to stop after SIGTERM.
const STOP_TIMEOUT: Duration = Duration::from_secs(10);
/// How long a write may wait for the service to read: far beyond any pace, so that only a
/// service that stopped reading fails it.
const WRITE_TIMEOUT: Duration = Duration::from_secs(5);
/// Lines of the service's log shown with a failure.
const LOG_TAIL_LINES: usize = 20;
/// Bits per byte on the line: 8N1.
const BITS_PER_BYTE: u64 = 10;

/// How the captures are played.
#[derive(Debug, Clone, Copy)]
pub struct GnssLiveOptions {
    /// Line rate, baud.
    pub baud: u32,
    /// Captures run at once.
    pub jobs: usize,
}

/// Plays every capture of `dir` to a running gnss service, `options.jobs` at a time, under a
/// progress bar; a capture that cannot be read or whose service fails is listed with the reason,
/// and the rest go on.
pub fn gnss_captures(dir: &Path, options: GnssLiveOptions) -> Result<LiveCapturesReport> {
    if options.baud == 0 {
        bail!("--baud 0: must be > 0");
    }
    let names = capture_names(dir)?;
    let shutdown = Shutdown::install()?;
    let exe = std::env::current_exe().context("cannot locate the rins executable")?;
    let n = names.len();
    let next = AtomicUsize::new(0);
    let mut outcomes: Vec<Option<Result<(CaptureResult, LiveCapture), String>>> =
        (0..n).map(|_| None).collect();
    let mut bar = Progress::new("eval gnss-captures live");
    bar.set(0, n);
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        for _ in 0..options.jobs.clamp(1, n) {
            let tx = tx.clone();
            let (next, names, exe, shutdown, dir) = (&next, &names, &exe, &shutdown, dir);
            scope.spawn(move || {
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= n || shutdown.requested() {
                        break;
                    }
                    let outcome = capture_live(dir, &names[i], options.baud, exe, shutdown);
                    if tx.send((i, outcome)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        for (done, (i, outcome)) in rx.iter().enumerate() {
            outcomes[i] = Some(outcome);
            bar.set(done + 1, n);
        }
    });
    bar.finish();
    if shutdown.requested() {
        bail!("stopped");
    }
    let mut runs = Vec::with_capacity(n);
    let mut failures = Vec::new();
    for (name, outcome) in names.into_iter().zip(outcomes) {
        match outcome {
            Some(Ok(run)) => runs.push(run),
            Some(Err(reason)) => failures.push(Failure { name, reason }),
            None => failures.push(Failure {
                name,
                reason: "not run".to_string(),
            }),
        }
    }
    Ok(build_live(runs, failures, options.baud))
}

/// One capture through its own service, scored; the reason as text when it failed.
fn capture_live(
    dir: &Path,
    name: &str,
    baud: u32,
    exe: &Path,
    shutdown: &Shutdown,
) -> Result<(CaptureResult, LiveCapture), String> {
    let (log, chk) = read_capture(dir, name).map_err(|e| format!("{e:#}"))?;
    let bytes = receiver_bytes(&log);
    let settings = private_settings("gl").map_err(|e| format!("{e:#}"))?;
    let service_log = std::env::temp_dir().join(format!("rins-gnss-live-{}.log", settings.prefix));
    let fed = feed_service(bytes, baud, exe, &settings, &service_log, shutdown);
    // Every process and port of the deployment is gone by now.
    rins_runtime::shm_cleanup::remove_all(&settings, true);
    let tail = log_tail(&service_log);
    let _ = std::fs::remove_file(&service_log);
    match fed {
        Ok(feed) => Ok(evaluate_live(name, &log, &chk, &feed)),
        Err(e) if tail.is_empty() => Err(format!("{e:#}")),
        Err(e) => Err(format!("{e:#}; the service's log ends:\n{tail}")),
    }
}

/// The last lines of the service's log (empty when there is none).
fn log_tail(path: &Path) -> String {
    let text = std::fs::read(path)
        .map(|b| String::from_utf8_lossy(&b).into_owned())
        .unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(LOG_TAIL_LINES)..].join("\n")
}

/// What is subscribed to before the service starts, so that nothing it publishes is missed.
struct Taps {
    fixes: TopicSubscriber<GnssFix>,
    link: TopicSubscriber<GnssLinkReport>,
    heartbeats: TopicSubscriber<Health>,
    feed: LiveFeed,
    /// A heartbeat of the gnss service arrived.
    beating: bool,
}

impl Taps {
    /// Takes everything queued; the subscribers' buffers are bounded, so this runs between
    /// writes.
    fn drain(&mut self) -> Result<()> {
        while let Some(fix) = self.fixes.receive()? {
            self.feed.fixes.push(fix);
        }
        while let Some(report) = self.link.receive()? {
            self.feed.link = Some(report);
        }
        while let Some(h) = self.heartbeats.receive()? {
            self.beating |= h.service == ServiceKind::Gnss as u8;
        }
        Ok(())
    }
}

/// `bytes` written at `baud` to a fresh gnss service on the deployment of `settings` (its log
/// into `service_log`), and what it published.
fn feed_service(
    bytes: &[u8],
    baud: u32,
    exe: &Path,
    settings: &IpcSettings,
    service_log: &Path,
    shutdown: &Shutdown,
) -> Result<LiveFeed> {
    let (mut line, receiver_end) = TTYPort::pair().context("cannot create a pseudo-terminal")?;
    // The receiver's end stays open here: the terminal outlives the service's opening and
    // closing of it, and holds what is written before the service reads.
    let tty = receiver_end
        .name()
        .context("the pseudo-terminal has no device name")?;
    line.set_timeout(WRITE_TIMEOUT)?;
    let tool = ToolNode::join_settings("eval-gnss", settings.clone())?;
    let node = tool.node();
    let mut taps = Taps {
        fixes: TopicSubscriber::new(node, names::GNSS)?,
        link: TopicSubscriber::new(node, names::GNSS_LINK)?,
        heartbeats: TopicSubscriber::new(node, names::HEARTBEAT)?,
        feed: LiveFeed::default(),
        beating: false,
    };
    let mut service = ServiceProcess::start(exe, &tty, settings, service_log)?;
    let started = Instant::now();
    while !taps.beating {
        service.check_running(shutdown)?;
        if started.elapsed() > START_TIMEOUT {
            bail!(
                "the gnss service did not beat within {} s",
                START_TIMEOUT.as_secs()
            );
        }
        taps.heartbeats.wait(Duration::from_millis(20))?;
        taps.drain()?;
    }
    let ns_per_byte = BITS_PER_BYTE * 1_000_000_000 / u64::from(baud);
    let pace = Instant::now();
    let mut written = 0_u64;
    for chunk in bytes.chunks(CHUNK_BYTES) {
        line.write_all(chunk).with_context(|| {
            format!("writing the line after {written} bytes (the service stopped reading?)")
        })?;
        written += chunk.len() as u64;
        taps.drain()?;
        service.check_running(shutdown)?;
        let due = pace + Duration::from_nanos(written * ns_per_byte);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
    }
    taps.feed.bytes_written = written;
    let quiet_from = Instant::now();
    while quiet_from.elapsed() < QUIET {
        service.check_running(shutdown)?;
        taps.fixes.wait(Duration::from_millis(20))?;
        taps.drain()?;
    }
    let status = service.stop()?;
    // What it published last (the final line report) is still queued.
    taps.drain()?;
    if !status.success() {
        bail!("the gnss service ended with {status} when stopped");
    }
    let Taps { feed, .. } = taps;
    drop(tool);
    Ok(feed)
}

/// The running gnss service; killed and reaped if it is still running when dropped (an error
/// on the way).
struct ServiceProcess {
    child: Option<Child>,
}

impl ServiceProcess {
    fn start(exe: &Path, tty: &str, settings: &IpcSettings, log: &Path) -> Result<Self> {
        let log_file =
            File::create(log).with_context(|| format!("cannot create {}", log.display()))?;
        let child = Command::new(exe)
            .args(["service", "gnss", "--port", tty])
            .env(ROOT_ENV, &settings.root)
            .env(PREFIX_ENV, &settings.prefix)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(log_file)
            .spawn()
            .with_context(|| format!("cannot start {} service gnss", exe.display()))?;
        Ok(Self { child: Some(child) })
    }

    /// An error when the service ended (it must run until stopped) or a stop was requested.
    fn check_running(&mut self, shutdown: &Shutdown) -> Result<()> {
        if shutdown.requested() {
            bail!("stopped");
        }
        if let Some(child) = &mut self.child
            && let Some(status) = child.try_wait()?
        {
            self.child = None;
            bail!("the gnss service ended on its own with {status}");
        }
        Ok(())
    }

    /// SIGTERM, then waits for the end; an error when it does not end in time.
    fn stop(&mut self) -> Result<ExitStatus> {
        let Some(child) = &mut self.child else {
            bail!("the gnss service is not running");
        };
        signal(child, libc::SIGTERM);
        let asked = Instant::now();
        loop {
            if let Some(status) = child.try_wait()? {
                self.child = None;
                return Ok(status);
            }
            if asked.elapsed() > STOP_TIMEOUT {
                bail!(
                    "the gnss service did not stop within {} s of SIGTERM",
                    STOP_TIMEOUT.as_secs()
                );
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for ServiceProcess {
    fn drop(&mut self) {
        if let Some(child) = &mut self.child {
            signal(child, libc::SIGKILL);
            let _ = child.wait();
        }
    }
}

fn signal(child: &Child, sig: libc::c_int) {
    if let Ok(pid) = i32::try_from(child.id()) {
        // SAFETY: kill(2) on our own child, not yet reaped.
        unsafe { libc::kill(pid, sig) };
    }
}
