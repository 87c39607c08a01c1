//! `rins soak --minutes N`: runs the whole pipeline (`rins up`) and kills a randomly chosen
//! service with SIGKILL every few seconds, while watching the navigation output as consumers see it
//! (both navigator lanes through the lane selector): how many samples never arrived (gaps in the
//! frame sequence), the longest silence, and samples that were not navigating. Prints a JSON summary.
//!
//! Faults come one at a time, as the redundancy is designed for: a kill waits until every service
//! is running again and, with two navigator lanes, until both lanes have settled solutions.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{HealthReport, NavMode, ServiceKind, ServiceState, names};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rins_runtime::ipc::{IpcSettings, TopicSubscriber, create_node};
use rins_runtime::lane_selector::{SelectorConfig, trusted};
use rins_runtime::nav_subscriber::NavSubscriber;
use rins_runtime::shutdown::Shutdown;
use rins_watchdog::seq_gaps::SeqGaps;
use serde::Serialize;

use crate::cli::SoakArgs;

/// Quiet time at the end of the run, so the last killed service is restarted and publishing
/// again when the pipeline is stopped.
const SETTLE: Duration = Duration::from_secs(3);

/// Services the soak kills (the watchdog and the simulator are the test harness here).
const VICTIMS: [ServiceKind; 5] = [
    ServiceKind::Acquisition,
    ServiceKind::Fusion,
    ServiceKind::Altimeter,
    ServiceKind::Navigator,
    ServiceKind::NavigatorStandby,
];

#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SoakSummary {
    pub minutes: f64,
    pub kills: u64,
    /// Kills per service, in the order of [`VICTIMS`].
    pub kills_by_service: Vec<(String, u64)>,
    /// Restarts the watchdog made (from its summary).
    pub restarts: u64,
    pub nav_samples: u64,
    /// Frames with no navigation output (gaps in the frame sequence of the `nav` topic).
    pub lost_nav_samples: u64,
    /// Longest wall-clock interval between two navigation samples, ms.
    pub max_gap_ms: f64,
    /// Samples after the first navigating one that were aligning again (a lane that could not
    /// recover its solution).
    pub not_navigating_samples: u64,
    /// Lane changes of the selector, and samples it took from the other lane to fill a hole.
    pub lane_switches: u64,
    pub lane_filled: u64,
    /// Kills put off because the pipeline had not recovered from the previous one yet.
    pub kills_deferred: u64,
    /// Shared-memory entries left after the pipeline stopped (from the watchdog's summary).
    pub shm_leaked: u64,
}

/// Tracks the navigation output: sequence gaps and the longest silence.
#[derive(Debug, Default)]
struct NavWatch {
    /// Sequence numbers missing from the stream (the watchdog's own count).
    gaps: SeqGaps,
    last_at: Option<Instant>,
    samples: u64,
    max_gap: Duration,
    navigated: bool,
    not_navigating: u64,
}

impl NavWatch {
    fn observe_mode(&mut self, mode: NavMode) {
        if mode == NavMode::Aligning {
            self.not_navigating += u64::from(self.navigated);
        } else {
            self.navigated = true;
        }
    }

    fn observe(&mut self, seq: u64, at: Instant) {
        self.gaps.observe(seq);
        if let Some(prev) = self.last_at {
            self.max_gap = self.max_gap.max(at - prev);
        }
        self.last_at = Some(at);
        self.samples += 1;
    }
}

/// How often a deferred kill looks again whether the pipeline recovered.
const RECHECK: Duration = Duration::from_millis(200);

/// A lane whose newest sample is this far behind the output is not publishing (killed, restarting).
const FRESH_SAMPLES: u64 = 100;

/// Every supervised process running, and every navigator lane that publishes holds a settled
/// solution: the pipeline is back to full redundancy and can take the next fault.
fn recovered(report: Option<&HealthReport>, nav: &NavSubscriber, newest_seq: u64) -> bool {
    let Some(report) = report else {
        return false;
    };
    let count = usize::from(report.count).min(report.services.len());
    let all_running = report.services[..count]
        .iter()
        .all(|s| ServiceState::from_u8(s.state) == Some(ServiceState::Running));
    let settle = SelectorConfig::default().settle;
    let lanes_settled = (0..ServiceKind::NAVIGATOR_LANES.len())
        .filter(|&lane| nav.lane_totals()[lane] > 0)
        .all(|lane| {
            nav.lane_latest(lane).is_some_and(|s| {
                trusted(s, settle) && s.header.origin_seq + FRESH_SAMPLES >= newest_seq
            })
        });
    all_running && lanes_settled
}

/// The pid of `kind` when the report shows it running.
fn running_pid(report: &HealthReport, kind: ServiceKind) -> Option<u32> {
    let count = usize::from(report.count).min(report.services.len());
    report.services[..count]
        .iter()
        .find(|s| {
            s.service == kind as u8 && ServiceState::from_u8(s.state) == Some(ServiceState::Running)
        })
        .map(|s| s.pid)
}

pub fn run(args: &SoakArgs) -> Result<()> {
    if !(args.minutes.is_finite() && args.minutes > 0.0 && args.minutes <= 24.0 * 60.0) {
        bail!("--minutes {}: must be in (0, 1440]", args.minutes);
    }
    if !(args.min_interval_s.is_finite()
        && args.min_interval_s >= 0.5
        && args.max_interval_s.is_finite()
        && args.max_interval_s >= args.min_interval_s)
    {
        bail!(
            "--min-interval {} / --max-interval {}: need 0.5 <= min <= max seconds",
            args.min_interval_s,
            args.max_interval_s
        );
    }
    let shutdown = Shutdown::install()?;
    let exe = std::env::current_exe().context("cannot locate the rins executable")?;
    let run_s = args.minutes * 60.0;
    let mut up = Command::new(exe)
        .args([
            "up",
            "--scenario",
            "uav",
            "--duration",
            &format!("{}", run_s + 60.0),
            "--json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .context("cannot start rins up")?;
    // The watchdog's stdout: a status line per second, the JSON summary last. Read on a thread so
    // the pipe never fills.
    let (lines_tx, lines) = std::sync::mpsc::channel::<String>();
    let stdout = up.stdout.take().context("rins up has no stdout")?;
    let reader = std::thread::spawn(move || {
        for line in std::io::BufRead::lines(std::io::BufReader::new(stdout)).map_while(Result::ok) {
            if lines_tx.send(line).is_err() {
                break;
            }
        }
    });
    // Join the deployment only once the watchdog runs: it refuses to start while another process
    // holds a node on the prefix, and this one would be such a process.
    if lines.recv_timeout(Duration::from_secs(120)).is_err() {
        // SAFETY: SIGTERM to our own child, not reaped yet.
        unsafe { libc::kill(up.id() as libc::pid_t, libc::SIGTERM) };
        let status = up.wait()?;
        bail!("rins up printed nothing within 120 s ({status})");
    }
    let settings = IpcSettings::from_env();
    let node = create_node(&format!("soak-{}", std::process::id()), &settings)?;
    let mut nav_in = NavSubscriber::new(&node)?;
    let health_in = TopicSubscriber::<HealthReport>::new(&node, names::HEALTH)?;
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut nav = NavWatch::default();
    let mut report: Option<HealthReport> = None;
    let mut kills = [0u64; VICTIMS.len()];
    let mut deferred = 0u64;

    // Wait for the pipeline to navigate before the clock starts.
    let ready_by = Instant::now() + Duration::from_secs(120);
    while nav.samples == 0 {
        if Instant::now() > ready_by || shutdown.requested() {
            bail!("the pipeline produced no navigation output within 120 s");
        }
        nav_in.wait(Duration::from_millis(100))?;
        while let Some(n) = nav_in.receive()? {
            nav.observe(n.header.origin_seq, Instant::now());
            nav.observe_mode(NavMode::from_u8(n.mode));
        }
    }
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(run_s);
    let mut next_kill = start
        + Duration::from_secs_f64(rng.random_range(args.min_interval_s..=args.max_interval_s));
    let mut next_progress = start + Duration::from_secs(10);
    while Instant::now() < end && !shutdown.requested() {
        nav_in.wait(Duration::from_millis(5))?;
        while let Some(n) = nav_in.receive()? {
            nav.observe(n.header.origin_seq, Instant::now());
            nav.observe_mode(NavMode::from_u8(n.mode));
        }
        while let Some(r) = health_in.receive()? {
            report = Some(r);
        }
        let now = Instant::now();
        // No kill in the last seconds: every killed service must be back before the summary.
        if now >= next_kill && now + SETTLE < end {
            if !recovered(report.as_ref(), &nav_in, nav.gaps.last().unwrap_or(0)) {
                deferred += 1;
                next_kill = now + RECHECK;
                continue;
            }
            let i = rng.random_range(0..VICTIMS.len());
            if let Some(pid) = report.as_ref().and_then(|r| running_pid(r, VICTIMS[i])) {
                // SAFETY: kill(2) on a pid the watchdog reports as one of its running children.
                if unsafe { libc::kill(pid as libc::pid_t, libc::SIGKILL) } == 0 {
                    kills[i] += 1;
                }
            }
            next_kill = now
                + Duration::from_secs_f64(
                    rng.random_range(args.min_interval_s..=args.max_interval_s),
                );
        }
        if now >= next_progress {
            eprintln!(
                "soak: {:.0}/{:.0} s, {} kills, {} nav samples lost, longest gap {:.1} ms",
                (now - start).as_secs_f64(),
                run_s,
                kills.iter().sum::<u64>(),
                nav.gaps.missing,
                nav.max_gap.as_secs_f64() * 1e3
            );
            next_progress += Duration::from_secs(10);
        }
    }
    let (lane_switches, lane_filled) = (nav_in.switches().0, nav_in.filled());
    drop(nav_in);
    drop(health_in);
    drop(node);
    // SAFETY: SIGTERM to our own child, not reaped yet: the watchdog stops everything cleanly.
    unsafe { libc::kill(up.id() as libc::pid_t, libc::SIGTERM) };
    let status = up.wait()?;
    let _ = reader.join();
    let up_summary: serde_json::Value = lines
        .try_iter()
        .last()
        .and_then(|l| serde_json::from_str(&l).ok())
        .with_context(|| format!("rins up ended ({status}) without its JSON summary"))?;
    let number = |key: &str| up_summary[key].as_u64().unwrap_or(0);
    let summary = SoakSummary {
        minutes: start.elapsed().as_secs_f64() / 60.0,
        kills: kills.iter().sum(),
        kills_by_service: VICTIMS
            .iter()
            .zip(kills)
            .map(|(k, n)| (k.name().to_string(), n))
            .collect(),
        restarts: number("restarts"),
        nav_samples: nav.samples,
        lost_nav_samples: nav.gaps.missing,
        max_gap_ms: nav.max_gap.as_secs_f64() * 1e3,
        not_navigating_samples: nav.not_navigating,
        lane_switches,
        lane_filled,
        kills_deferred: deferred,
        shm_leaked: number("shm_leaked"),
    };
    println!("{}", serde_json::to_string(&summary)?);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nav_watch_counts_missing_frames_and_the_longest_silence() {
        let t0 = Instant::now();
        let mut w = NavWatch::default();
        for (seq, ms) in [(10, 0), (11, 1), (15, 40), (16, 41), (14, 42), (17, 43)] {
            w.observe(seq, t0 + Duration::from_millis(ms));
        }
        // 12, 13, 14 missing at the jump; the late 14 does not undo the count nor move the seq back.
        assert_eq!(w.gaps.missing, 3);
        assert_eq!(w.samples, 6);
        assert_eq!(w.gaps.last(), Some(17));
        assert_eq!(w.max_gap, Duration::from_millis(39));
    }
}
