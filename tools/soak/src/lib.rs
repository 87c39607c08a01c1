//! `rins soak --minutes N`: runs the whole pipeline (`rins up`) and, every few seconds, a random
//! fault of the kinds asked for (`--faults`): a SIGKILL or a SIGSTOP of a service, a fault on one
//! sensor channel, the serial device unplugged. Meanwhile it watches the navigation output as
//! consumers see it (both navigator lanes through the lane selector): how many samples never
//! arrived (gaps in the frame sequence), the longest silence, samples that were not navigating,
//! and what each kind of fault cost. Prints a JSON summary.
//!
//! Faults come one at a time, as the redundancy is designed for: the next waits until every
//! service is running again, the navigation output flows, both navigator lanes hold settled
//! solutions and every sensor channel is back in the fused solution.

mod args;
mod fault_ledger;
mod fault_plan;
mod nav_watch;
mod summary;

pub use args::SoakArgs;
pub use summary::SoakSummary;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use ipc_types::{
    ChannelState, FusedImu, HealthReport, ServiceKind, ServiceState, fused_flags, names,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rins_navigator::lanes::{NavSubscriber, SelectorConfig, trusted};
use rins_runtime::ipc::{IpcSettings, TopicSubscriber, create_node};
use rins_runtime::shutdown::Shutdown;
use rins_sim::fault_command::ChannelId;

use args::check_args;
use fault_ledger::FaultLedger;
use fault_plan::{Fault, FaultKind};
use nav_watch::NavWatch;

/// How `rins` starts the line of an error it exits with.
const UP_ERROR: &str = "rins: error:";

/// Quiet time at the end of the run, beyond the longest recovery of the kinds asked for, so the
/// last fault is over and every service publishing again when the pipeline is stopped.
const SETTLE: Duration = Duration::from_secs(3);

/// How often a deferred fault looks again whether the pipeline recovered.
const RECHECK: Duration = Duration::from_millis(200);

/// A pipeline not back to full redundancy this long after a fault began is reported unrecovered
/// (and the soak goes on with the next fault).
const RECOVERY_LIMIT: Duration = Duration::from_secs(30);

/// A lane whose newest sample is this far behind the output is not publishing (killed, restarting).
const FRESH_SAMPLES: u64 = 100;

/// The navigation output flows when its newest sample is at most this old.
const FLOWING: Duration = Duration::from_millis(100);

/// A cleared channel is readmitted this much later, once its samples are healthy again.
const READMIT_AFTER: Duration = Duration::from_millis(200);

/// What the soak last heard from the pipeline.
#[derive(Default)]
struct Latest {
    health: Option<HealthReport>,
    fused: Option<FusedImu>,
}

/// Every sensor channel fitted is in the fused solution and no fault awaits isolation.
fn all_channels_in(fused: &FusedImu) -> bool {
    let ok = |states: &[u8], n: u8| {
        states
            .iter()
            .take(usize::from(n))
            .all(|&s| ChannelState::from_u8(s) == Some(ChannelState::Ok))
    };
    let pending = fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED
        | fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED;
    ok(&fused.gyro_state, fused.n_gyro)
        && ok(&fused.accel_state, fused.n_accel)
        && fused.flags & pending == 0
}

/// Full redundancy again: every supervised process running, the navigation output flowing, every
/// navigator lane that publishes holding a settled solution, every sensor channel in use.
fn recovered(latest: &Latest, nav: &NavSubscriber, watch: &NavWatch, now: Instant) -> bool {
    let (Some(report), Some(fused)) = (latest.health.as_ref(), latest.fused.as_ref()) else {
        return false;
    };
    let count = usize::from(report.count).min(report.services.len());
    let all_running = report.services[..count]
        .iter()
        .all(|s| ServiceState::from_u8(s.state) == Some(ServiceState::Running));
    let flowing = watch
        .last_at
        .is_some_and(|t| now.saturating_duration_since(t) <= FLOWING);
    let newest_seq = watch.gaps.last().unwrap_or(0);
    let settle = SelectorConfig::default().settle;
    let lanes_settled = (0..ServiceKind::NAVIGATOR_LANES.len())
        .filter(|&lane| nav.lane_totals()[lane] > 0)
        .all(|lane| {
            nav.lane_latest(lane).is_some_and(|s| {
                trusted(s, settle) && s.header.origin_seq + FRESH_SAMPLES >= newest_seq
            })
        });
    all_running && flowing && lanes_settled && all_channels_in(fused)
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

/// Runs `rins ARGS` (a tool on the same deployment: the environment carries its IPC prefix) and
/// turns a failure into its message.
fn rins_tool(exe: &Path, args: &[&str]) -> Result<(), String> {
    let out = Command::new(exe)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .output()
        .map_err(|e| format!("rins {}: cannot run: {e}", args.join(" ")))?;
    if out.status.success() {
        return Ok(());
    }
    Err(format!(
        "rins {}: {} ({})",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr).trim(),
        out.status
    ))
}

/// A channel fault from start to end, as an operator would run it: inject, hold, clear, readmit.
fn sensor_fault(
    exe: &Path,
    channel: ChannelId,
    fault: ipc_types::SimFault,
    hold: Duration,
) -> Result<(), String> {
    let ch = channel.to_string();
    rins_tool(exe, &["inject", &ch, fault.name()])?;
    std::thread::sleep(hold);
    rins_tool(exe, &["inject", &ch, "clear"])?;
    std::thread::sleep(READMIT_AFTER);
    rins_tool(exe, &["readmit", &ch])
}

/// A fault the soak has begun.
struct Active {
    began: Instant,
    /// The commands of a sensor fault or an unplug, run on their own thread so that the soak
    /// keeps reading the output meanwhile.
    action: Option<JoinHandle<Result<(), String>>>,
    /// Reported unrecovered already.
    overdue: bool,
}

/// Signals `pid` (one of the watchdog's running children) with `signal`.
fn signal(pid: u32, signal: libc::c_int) -> Result<(), String> {
    let pid = libc::pid_t::try_from(pid).map_err(|_| format!("pid {pid} out of range"))?;
    // SAFETY: kill(2) on a pid the watchdog reports as one of its running children.
    if unsafe { libc::kill(pid, signal) } == 0 {
        Ok(())
    } else {
        Err(format!(
            "kill({pid}, {signal}): {}",
            std::io::Error::last_os_error()
        ))
    }
}

/// Runs a fault's commands on their own thread.
fn in_background(
    exe: &Path,
    commands: impl FnOnce(&Path) -> Result<(), String> + Send + 'static,
) -> JoinHandle<Result<(), String>> {
    let exe: PathBuf = exe.to_path_buf();
    std::thread::spawn(move || commands(&exe))
}

/// Begins `fault`; an immediate failure is returned, a later one comes from the action's thread.
fn begin(fault: Fault, exe: &Path, report: &HealthReport) -> Result<Active, String> {
    let began = Instant::now();
    let pid_of = |kind: ServiceKind| {
        running_pid(report, kind).ok_or_else(|| format!("{} is not running", kind.name()))
    };
    let action = match fault {
        Fault::Kill(kind) => {
            signal(pid_of(kind)?, libc::SIGKILL)?;
            None
        }
        Fault::Hang(kind) => {
            signal(pid_of(kind)?, libc::SIGSTOP)?;
            None
        }
        Fault::Sensor {
            channel,
            fault,
            hold,
        } => Some(in_background(exe, move |exe| {
            sensor_fault(exe, channel, fault, hold)
        })),
        Fault::Disconnect { duration_s } => Some(in_background(exe, move |exe| {
            let duration = format!("{duration_s:.3}");
            rins_tool(exe, &["inject", "disconnect", "--duration", &duration])
        })),
    };
    Ok(Active {
        began,
        action,
        overdue: false,
    })
}

/// The longest time a fault of `kind` may take before the pipeline can be whole again (its own
/// duration and the watchdog's reaction), for the quiet time at the end of the run.
fn recovery_allowance(kind: FaultKind) -> Duration {
    Duration::from_secs_f64(match kind {
        FaultKind::Kill => 0.5,
        // The built-in heartbeat timeout (3 s), the health report period, the restart.
        FaultKind::Hang => 4.5,
        FaultKind::Sensor => fault_plan::SENSOR_HOLD_S.1 + 1.5,
        // The unplug, then the reconnect backoff (at most 1 s late).
        FaultKind::Disconnect => fault_plan::DISCONNECT_S.1 + 1.5,
    })
}

/// Runs a soak: starts `rins up` (the `uav` scenario), waits for navigation output, injects faults
/// for `args.minutes` (or until the process is asked to stop), stops the pipeline and prints a
/// [`SoakSummary`]: as one JSON line on stdout with `args.json`, else as text (progress goes to
/// stderr). Fails on invalid
/// arguments, when `rins up` cannot be started, prints nothing or produces no navigation output
/// within 120 s, or ends without its JSON summary.
pub fn run(args: &SoakArgs) -> Result<()> {
    let kinds = check_args(args)?;
    let shutdown = Shutdown::install()?;
    let exe = std::env::current_exe().context("cannot locate the rins executable")?;
    let run_s = args.minutes * 60.0;
    let mut up = Command::new(&exe)
        .args([
            "up",
            "--scenario",
            "uav",
            "--duration",
            &format!("{}", run_s + 60.0),
            "--json",
            "--profile",
            &args.profile,
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("cannot start rins up")?;
    // With --json the watchdog's stdout is its JSON summary alone; its stderr has a status line
    // per second (and the children's logs). Both read on threads so that no pipe fills.
    let (lines_tx, lines) = std::sync::mpsc::channel::<String>();
    let stdout = up.stdout.take().context("rins up has no stdout")?;
    let reader = std::thread::spawn(move || forward_lines(stdout, &lines_tx, |_| true));
    let (status_tx, status_lines) = std::sync::mpsc::channel::<String>();
    let stderr = up.stderr.take().context("rins up has no stderr")?;
    let status_reader = std::thread::spawn(move || {
        forward_lines(stderr, &status_tx, |l| {
            l.starts_with("t=") || l.starts_with(UP_ERROR)
        });
    });
    // Join the deployment only once the watchdog runs (its first status line): it refuses to
    // start while another process holds a node on the prefix, and this one would be such a
    // process.
    match status_lines.recv_timeout(Duration::from_secs(120)) {
        Ok(line) if line.starts_with(UP_ERROR) => {
            // It refused to start (a --profile the machine cannot run, say): its own words.
            let status = up.wait()?;
            let why = line.trim_start_matches(UP_ERROR).trim();
            bail!("rins up did not start ({status}): {why}");
        }
        Ok(_) => {}
        Err(_) => {
            // SAFETY: SIGTERM to our own child, not reaped yet.
            unsafe { libc::kill(up.id() as libc::pid_t, libc::SIGTERM) };
            let status = up.wait()?;
            bail!("rins up printed nothing within 120 s ({status})");
        }
    }
    // The deployment is the one this soak started, so its own user's: checked like any other
    // before it is joined (another user's files on the prefix are never read).
    let settings = IpcSettings::from_env();
    if let Err(e) = rins_runtime::join_check::check_joinable(&settings) {
        // SAFETY: SIGTERM to our own child, not reaped yet.
        unsafe { libc::kill(up.id() as libc::pid_t, libc::SIGTERM) };
        let _ = up.wait();
        return Err(e);
    }
    let node = create_node(&format!("soak-{}", std::process::id()), &settings)?;
    let mut nav_in = NavSubscriber::new(&node)?;
    let health_in = TopicSubscriber::<HealthReport>::new(&node, names::HEALTH)?;
    let fused_in = TopicSubscriber::<FusedImu>::new(&node, names::FUSED_IMU)?;
    let mut rng = ChaCha8Rng::seed_from_u64(args.seed);
    let mut nav = NavWatch::default();
    let mut latest = Latest::default();
    let mut ledger = FaultLedger::new(&kinds);
    let mut active: Option<Active> = None;
    let mut deferred = 0u64;
    let quiet = SETTLE
        + kinds
            .iter()
            .map(|&k| recovery_allowance(k))
            .max()
            .unwrap_or_default();

    // Wait for the pipeline to navigate before the clock starts.
    let ready_by = Instant::now() + Duration::from_secs(120);
    while nav.samples == 0 {
        if Instant::now() > ready_by || shutdown.requested() {
            bail!("the pipeline produced no navigation output within 120 s");
        }
        nav_in.wait(Duration::from_millis(100))?;
        nav.drain(&mut nav_in)?;
    }
    let start = Instant::now();
    let end = start + Duration::from_secs_f64(run_s);
    let interval = |rng: &mut ChaCha8Rng| {
        Duration::from_secs_f64(rng.random_range(args.min_interval_s..=args.max_interval_s))
    };
    let mut next_fault = start + interval(&mut rng);
    let mut next_progress = start + Duration::from_secs(10);
    while Instant::now() < end && !shutdown.requested() {
        nav_in.wait(Duration::from_millis(5))?;
        nav.drain(&mut nav_in)?;
        while let Some(r) = health_in.receive()? {
            latest.health = Some(r);
        }
        while let Some(f) = fused_in.receive()? {
            latest.fused = Some(f);
        }
        let now = Instant::now();
        if let Some(a) = active.as_mut()
            && a.action.as_ref().is_some_and(JoinHandle::is_finished)
            && let Some(handle) = a.action.take()
        {
            let outcome = handle
                .join()
                .unwrap_or_else(|_| Err("the fault's thread panicked".into()));
            if let Err(e) = outcome {
                eprintln!("soak: fault failed: {e}");
                ledger.failed();
            }
        }
        // No fault in the last seconds: every fault must be over before the summary.
        if now >= next_fault && now + quiet < end {
            let busy = active.as_ref().is_some_and(|a| a.action.is_some());
            if busy || !recovered(&latest, &nav_in, &nav, now) {
                if let Some(a) = active.as_mut()
                    && !a.overdue
                    && now - a.began > RECOVERY_LIMIT
                {
                    eprintln!(
                        "soak: not back to full redundancy {} s after the last fault; going on",
                        RECOVERY_LIMIT.as_secs()
                    );
                    a.overdue = true;
                    ledger.unrecovered();
                }
                if busy || !active.as_ref().is_some_and(|a| a.overdue) {
                    deferred += 1;
                    next_fault = now + RECHECK;
                    continue;
                }
            }
            let channels = latest
                .fused
                .as_ref()
                .map_or((0, 0), |f| (f.n_gyro, f.n_accel));
            let fault = fault_plan::draw(&kinds, channels, &mut rng);
            ledger.begin(
                fault.kind(),
                fault.target(),
                nav.gaps.missing,
                nav.take_window_gap(),
            );
            let begun = match latest.health.as_ref() {
                Some(report) => begin(fault, &exe, report),
                None => Err("no health report from the watchdog yet".into()),
            };
            active = match begun {
                Ok(a) => Some(a),
                Err(e) => {
                    eprintln!(
                        "soak: cannot begin {} on {}: {e}",
                        fault.kind(),
                        fault.target()
                    );
                    ledger.failed();
                    None
                }
            };
            next_fault = now + interval(&mut rng);
        }
        if now >= next_progress {
            let done: Vec<String> = ledger
                .figures()
                .iter()
                .map(|(k, f)| format!("{k} {}", f.count))
                .collect();
            eprintln!(
                "soak: {:.0}/{:.0} s, faults: {}; {} nav samples lost, longest gap {:.1} ms",
                (now - start).as_secs_f64(),
                run_s,
                done.join(", "),
                nav.gaps.missing,
                nav.max_gap.as_secs_f64() * 1e3
            );
            next_progress += Duration::from_secs(10);
        }
    }
    ledger.close(nav.gaps.missing, nav.take_window_gap());
    let (lane_switches, lane_filled) = (nav_in.switches().0, nav_in.filled());
    drop((nav_in, health_in, fused_in, node));
    // A fault's commands still running (the run was interrupted) end on their own within seconds.
    if let Some(handle) = active.and_then(|a| a.action) {
        let _ = handle.join();
    }
    // SAFETY: SIGTERM to our own child, not reaped yet: the watchdog stops everything cleanly.
    unsafe { libc::kill(up.id() as libc::pid_t, libc::SIGTERM) };
    let status = up.wait()?;
    let _ = reader.join();
    drop(status_lines);
    let _ = status_reader.join();
    let up_summary: serde_json::Value = lines
        .try_iter()
        .last()
        .and_then(|l| serde_json::from_str(&l).ok())
        .with_context(|| format!("rins up ended ({status}) without its JSON summary"))?;
    let number = |key: &str| up_summary[key].as_u64().unwrap_or(0);
    let text = |key: &str| up_summary[key].as_str().unwrap_or_default().to_string();
    let summary = SoakSummary {
        minutes: start.elapsed().as_secs_f64() / 60.0,
        kills: ledger.count(FaultKind::Kill),
        restarts: number("restarts"),
        nav_samples: nav.samples,
        lost_nav_samples: nav.gaps.missing,
        max_gap_ms: nav.max_gap.as_secs_f64() * 1e3,
        not_navigating_samples: nav.not_navigating,
        lane_switches,
        lane_filled,
        faults_deferred: deferred,
        faults: ledger.figures().clone(),
        shm_leaked: number("shm_leaked"),
        profile: text("profile"),
        profile_reason: text("profile_reason"),
    };
    if args.json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        print!("{}", summary.to_text());
    }
    Ok(())
}

/// Sends the lines of `from` that `keep` accepts on `to`, reading on to the end even after the
/// receiver is gone, so that the writer never blocks on a full pipe.
fn forward_lines(
    from: impl std::io::Read,
    to: &std::sync::mpsc::Sender<String>,
    keep: impl Fn(&str) -> bool,
) {
    for line in std::io::BufRead::lines(std::io::BufReader::new(from)).map_while(Result::ok) {
        if keep(&line) {
            let _ = to.send(line);
        }
    }
}
