//! The watchdog's loop once every child runs: drain the topics, reap and restart children, kill
//! the hung ones, publish the health report, print the status line, until a stop is requested, the
//! run's duration ends, or a child exits more often than its restart limit allows.

use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use ipc_types::ServiceKind;
use rins_runtime::error_chain::ErrorChain;
use rins_runtime::ipc::IpcSettings;
use rins_runtime::payload::OtherVersionWarning;
use rins_runtime::shutdown::Shutdown;

use crate::child_exit_wait::ChildExitWait;
use crate::config::WatchdogConfig;
use crate::health_publisher::HealthPublisher;
use crate::kill_decisions::{kill_hung, kill_overdue_outputs, sweep_dead_nodes};
use crate::monitor::{COUNTED, Monitor};
use crate::output_deadline::OutputDeadline;
use crate::restart_policy::GiveUp;
use crate::restart_timing::RestartTiming;
use crate::status::status_line;
use crate::supervisor::{ChildEvent, FAILED_STARTS_LIMIT, Supervisor};

/// Period of the supervision loop: topics drained and children checked this often. Each turn
/// wakes the watchdog and asks every topic and child; at 1 ms that was the pipeline's largest CPU
/// share (12 % of a core, more than any stage), and at 5 ms still a fifth of a wake-up per 1 kHz
/// frame. At 20 ms a turn drains 20 samples of a 1 kHz topic (320 at 16 kHz) from a 512-sample
/// queue, and deadline times are measured to 20 ms, well inside their limits (0.5 s output
/// deadline, 3 s heartbeat timeout). A child's exit and a due restart do not wait for a turn
/// ([`ChildExitWait`], [`Supervisor::next_restart`]).
const LOOP_PERIOD: Duration = Duration::from_millis(20);

/// What a run of the loop is bound by: the deployment, the watchdog's settings, when it started
/// and when it ends.
pub struct Supervision<'a> {
    /// The deployment's IPC settings (dead nodes are looked up there).
    pub settings: &'a IpcSettings,
    /// `[watchdog]` of the configuration.
    pub config: &'a WatchdogConfig,
    /// Set by a termination signal: the loop returns at its next turn.
    pub shutdown: &'a Shutdown,
    /// When the deployment started (the status line's time).
    pub started: Instant,
    /// When a timed run ends (`rins up --duration`); none runs until stopped.
    pub end: Option<Instant>,
    /// The status lines go to stderr: stdout carries one JSON document (`rins up --json`).
    pub status_on_stderr: bool,
}

/// What the supervision loop drives.
pub struct Watch<'a> {
    /// The children.
    pub supervisor: &'a mut Supervisor,
    /// The topics the watchdog counts.
    pub monitor: &'a mut Monitor,
    /// The health report it publishes.
    pub health: &'a mut HealthPublisher,
    /// Restart-to-publish times.
    pub timing: &'a mut RestartTiming,
}

/// Runs the loop until a stop is requested or the run's end; an error when a child exits more
/// often than its restart limit allows and its policy is to stop the pipeline.
pub fn supervise(run: &Supervision<'_>, watch: Watch<'_>) -> Result<()> {
    let Watch {
        supervisor,
        monitor,
        health,
        timing,
    } = watch;
    let cfg = run.config;
    let mut deadline = (cfg.output_deadline_s > 0.0)
        .then(|| OutputDeadline::new(Duration::from_secs_f64(cfg.output_deadline_s)));
    let mut status = StatusLines::new(cfg.status_period_s, monitor, run.status_on_stderr);
    let mut events = Vec::new();
    let mut version_warning = OtherVersionWarning::new();
    let child_exit = ChildExitWait::new();
    while !run.shutdown.requested() && run.end.is_none_or(|e| Instant::now() < e) {
        monitor.drain()?;
        version_warning.check("watchdog", monitor.other_version());
        timing.observe(Instant::now(), |kind| monitor.output_count(kind));
        supervisor.poll(&mut events);
        if let Some(deadline) = deadline.as_mut() {
            kill_overdue_outputs(deadline, monitor, supervisor, Instant::now());
        }
        if let Some(report) = health.tick(supervisor, monitor)? {
            sweep_dead_nodes(run.settings, supervisor);
            if cfg.heartbeat_timeout_s > 0.0 {
                kill_hung(&report, supervisor);
            }
        }
        for event in events.drain(..) {
            on_child_event(event, run.settings, monitor, timing)?;
        }
        status.print_if_due(run.started, monitor);
        supervisor.sample_usage_if_due(Instant::now());
        // The next turn: at the period, at a pending restart's time, or when a child exits.
        let now = Instant::now();
        let turn = supervisor.next_restart().map_or(LOOP_PERIOD, |at| {
            at.saturating_duration_since(now).min(LOOP_PERIOD)
        });
        child_exit.sleep(turn);
    }
    Ok(())
}

/// Logs what happened to a child and frees what a dead one left in shared memory; an error when
/// the child was given up and its policy is to stop the pipeline.
fn on_child_event(
    event: ChildEvent,
    settings: &IpcSettings,
    monitor: &Monitor,
    timing: &mut RestartTiming,
) -> Result<()> {
    match event {
        ChildEvent::Exited {
            name,
            status,
            restart_in,
        } => {
            tracing::warn!(child = %name, %status, restart_in_ms = restart_in.as_millis() as u64, "child exited");
            if let Some(kind) = ServiceKind::from_name(&name)
                && let Some(count) = monitor.output_count(kind)
            {
                timing.on_exit(kind, Instant::now(), count);
            }
            // Its node is dead now: free its shared memory before the restart.
            match rins_runtime::ipc::remove_dead_nodes(settings) {
                Ok(n) if n > 0 => {
                    tracing::info!(child = %name, nodes = n, "removed the resources of dead nodes")
                }
                Ok(_) => {}
                Err(e) => tracing::warn!(error = %ErrorChain(&e), "cannot clean up dead nodes"),
            }
        }
        ChildEvent::Restarted { name, pid } => {
            tracing::info!(child = %name, pid, "child restarted")
        }
        ChildEvent::GaveUp {
            name,
            status,
            exits,
            window,
            action,
            failed_starts,
        } => {
            let mut why = if failed_starts >= FAILED_STARTS_LIMIT {
                format!(
                    "{name} failed to start {failed_starts} times in a row (last: {status}); its \
                     own error is above"
                )
            } else {
                format!(
                    "{name} exited ({status}) {exits} times within {:.0} s, more than \
                     watchdog.max_restarts allows (watchdog.services.{name} may raise it)",
                    window.as_secs_f64()
                )
            };
            // A damaged management segment makes every node creation fail: said here too, with
            // the file, whatever the child managed to print.
            if let Err(e) = rins_runtime::ipc::mgmt_segment::check(settings) {
                why.push_str(&format!(". {e}"));
            }
            if let Err(e) = rins_runtime::ipc::remove_dead_nodes(settings) {
                tracing::warn!(error = %ErrorChain(&e), "cannot clean up dead nodes");
            }
            match action {
                GiveUp::Shutdown => bail!("{why}: stopping the pipeline"),
                GiveUp::LeaveDown => {
                    tracing::error!("{why}: left down, the other services go on")
                }
            }
        }
    }
    Ok(())
}

/// The status line printed every `[watchdog] status_period_s` (none when 0), with the rates since
/// the last one.
struct StatusLines {
    period: Option<Duration>,
    next: Option<Instant>,
    last_totals: [u64; COUNTED.len()],
    last_at: Instant,
    on_stderr: bool,
}

impl StatusLines {
    fn new(period_s: f64, monitor: &Monitor, on_stderr: bool) -> Self {
        let period = (period_s > 0.0).then(|| Duration::from_secs_f64(period_s));
        Self {
            period,
            next: period.map(|p| Instant::now() + p),
            last_totals: monitor.totals,
            last_at: Instant::now(),
            on_stderr,
        }
    }

    fn print_if_due(&mut self, started: Instant, monitor: &Monitor) {
        let (Some(due), Some(period)) = (self.next, self.period) else {
            return;
        };
        if Instant::now() < due {
            return;
        }
        let dt = self.last_at.elapsed().as_secs_f64();
        let mut rates = [0.0; COUNTED.len()];
        for (i, rate) in rates.iter_mut().enumerate() {
            *rate = (monitor.totals[i] - self.last_totals[i]) as f64 / dt;
        }
        self.last_totals = monitor.totals;
        self.last_at = Instant::now();
        let mut line = status_line(
            started.elapsed().as_secs_f64(),
            &rates,
            monitor.nav_gaps.missing,
            &monitor.device_counters(),
            &monitor.redundancy_report(rins_runtime::clock::monotonic_ns()),
            monitor.last_nav.as_ref(),
        );
        // Only when the line is wrong, so the usual line keeps its width.
        if let Some(note) = monitor.link.status_note() {
            line.push_str(&format!(" | {note}"));
        }
        if self.on_stderr {
            eprintln!("{line}");
        } else {
            println!("{line}");
        }
        self.next = Some(due + period);
    }
}
