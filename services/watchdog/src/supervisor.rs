//! Child processes of the watchdog: start, notice exits, restart with backoff within each child's
//! restart limit (then give up on it), stop cleanly.

use std::os::unix::process::CommandExt;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use crate::process_usage::{ProcessUsage, UsageTracker, ticks_per_second};
use crate::restart_policy::{GiveUp, RestartPolicy, RestartWindow};

/// Starts in a row that failed — the child exited by itself with an error before it ran
/// [`RestartPolicy::stable_after`] — after which the child is given up even within its restart
/// limit. With the backoff capped at a few seconds, a child that can never start (its node cannot
/// be created, say) would otherwise be restarted for ever without reaching the limit, and its
/// stage would be down with nothing but a restart count to show for it.
pub const FAILED_STARTS_LIMIT: u32 = 5;

/// How to start one child, and how to restart it.
#[derive(Debug, Clone, PartialEq)]
pub struct ChildSpec {
    /// The child's name (its service's name).
    pub name: String,
    /// The program to run.
    pub program: PathBuf,
    /// Its arguments.
    pub args: Vec<String>,
    /// How it is restarted.
    pub policy: RestartPolicy,
    /// Stopped only after every child without it has stopped. `rins up` stops the device's
    /// readers first: no sample is published after its consumers are gone, and no reader sees its
    /// device (the simulator) vanish while it stops.
    pub stops_last: bool,
}

struct Managed {
    spec: ChildSpec,
    child: Option<Child>,
    started_at: Instant,
    failures: u32,
    restart_at: Option<Instant>,
    restarts: u64,
    window: RestartWindow,
    given_up: bool,
    /// Starts in a row that failed (see [`FAILED_STARTS_LIMIT`]).
    failed_starts: u32,
}

/// Every running child (name, pid) and this process as `watchdog`. A child is listed only while
/// it has not been reaped, so its pid cannot have been reused by another process.
fn processes(children: &[Managed]) -> impl Iterator<Item = (&str, u32)> {
    children
        .iter()
        .filter_map(|m| m.child.as_ref().map(|c| (m.spec.name.as_str(), c.id())))
        .chain(std::iter::once(("watchdog", std::process::id())))
}

/// The children of the watchdog: started, reaped, restarted, stopped.
#[derive(Default)]
pub struct Supervisor {
    children: Vec<Managed>,
    usage: UsageTracker,
}

/// One child as [`Supervisor::children`] reports it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ChildStatus {
    /// The child's name.
    pub name: String,
    /// `None` while the child waits out its restart backoff or was given up.
    pub pid: Option<u32>,
    /// Times it was restarted.
    pub restarts: u64,
    /// It exceeded its restart limit and is no longer restarted.
    pub given_up: bool,
}

/// What happened to a child during [`Supervisor::poll`].
#[derive(Debug, Clone, PartialEq)]
pub enum ChildEvent {
    /// The child exited; it is restarted after `restart_in`.
    Exited {
        /// The child.
        name: String,
        /// How it exited.
        status: String,
        /// Delay before the restart.
        restart_in: Duration,
    },
    /// The child was started again.
    Restarted {
        /// The child.
        name: String,
        /// Its new pid.
        pid: u32,
    },
    /// The child exited more often than its limit allows within its window: it is not restarted.
    GaveUp {
        /// The child.
        name: String,
        /// How it exited last.
        status: String,
        /// Exits within the window.
        exits: usize,
        /// The window.
        window: Duration,
        /// What giving up does.
        action: GiveUp,
        /// Starts in a row that failed; [`FAILED_STARTS_LIMIT`] of them give the child up even
        /// within its restart limit.
        failed_starts: u32,
    },
}

fn spawn(spec: &ChildSpec) -> Result<Child> {
    let mut cmd = Command::new(&spec.program);
    cmd.args(&spec.args).stdin(Stdio::null());
    // Children never write to our stdout: it carries the status lines and the final JSON.
    let stderr = std::io::stderr();
    let err_fd = std::os::fd::AsFd::as_fd(&stderr).try_clone_to_owned()?;
    cmd.stdout(Stdio::from(err_fd));
    // SAFETY: prctl is async-signal-safe; it only asks the kernel to SIGTERM the child when the
    // watchdog dies, so no orphan keeps running after a watchdog crash.
    unsafe {
        cmd.pre_exec(|| {
            libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGTERM);
            Ok(())
        });
    }
    cmd.spawn()
        .with_context(|| format!("cannot start {} ({:?})", spec.name, spec.program))
}

impl Supervisor {
    /// A supervisor with no child.
    pub fn new() -> Self {
        Self::default()
    }

    /// Starts a child now and supervises it from then on.
    pub fn start(&mut self, spec: ChildSpec) -> Result<u32> {
        let child = spawn(&spec)?;
        let pid = child.id();
        tracing::info!(child = %spec.name, pid, "started");
        self.children.push(Managed {
            window: RestartWindow::new(&spec.policy),
            spec,
            child: Some(child),
            started_at: Instant::now(),
            failures: 0,
            restart_at: None,
            restarts: 0,
            given_up: false,
            failed_starts: 0,
        });
        Ok(pid)
    }

    /// When the earliest restart is due, if one is pending.
    pub fn next_restart(&self) -> Option<Instant> {
        self.children.iter().filter_map(|m| m.restart_at).min()
    }

    /// Reaps exited children and restarts the ones whose backoff has passed.
    pub fn poll(&mut self, events: &mut Vec<ChildEvent>) {
        let now = Instant::now();
        for m in &mut self.children {
            if let Some(child) = &mut m.child {
                match child.try_wait() {
                    Ok(Some(status)) => {
                        m.child = None;
                        let policy = &m.spec.policy;
                        // Killed by a signal (a kill storm, a hung child's SIGKILL) is no failure
                        // of the start itself.
                        let failed_start = now - m.started_at < policy.stable_after
                            && status.code().is_some_and(|code| code != 0);
                        m.failed_starts = if failed_start {
                            m.failed_starts.saturating_add(1)
                        } else {
                            0
                        };
                        let within_limit = m.window.allow_restart(now);
                        if !within_limit || m.failed_starts >= FAILED_STARTS_LIMIT {
                            m.given_up = true;
                            events.push(ChildEvent::GaveUp {
                                name: m.spec.name.clone(),
                                status: status.to_string(),
                                exits: m.window.exits(),
                                window: policy.window,
                                action: policy.give_up,
                                failed_starts: m.failed_starts,
                            });
                            continue;
                        }
                        m.failures = policy.failures_after_exit(m.failures, now - m.started_at);
                        let delay = policy.backoff(m.failures);
                        m.restart_at = Some(now + delay);
                        events.push(ChildEvent::Exited {
                            name: m.spec.name.clone(),
                            status: status.to_string(),
                            restart_in: delay,
                        });
                    }
                    Ok(None) => {}
                    Err(e) => {
                        tracing::error!(child = %m.spec.name, error = %e, "cannot query child")
                    }
                }
            }
            if m.child.is_none() && m.restart_at.is_some_and(|at| now >= at) {
                match spawn(&m.spec) {
                    Ok(child) => {
                        events.push(ChildEvent::Restarted {
                            name: m.spec.name.clone(),
                            pid: child.id(),
                        });
                        m.child = Some(child);
                        m.started_at = now;
                        m.restart_at = None;
                        m.restarts += 1;
                    }
                    Err(e) => {
                        m.failures = m.failures.saturating_add(1);
                        m.restart_at = Some(now + m.spec.policy.backoff(m.failures));
                        tracing::error!(child = %m.spec.name, error = %e, "restart failed");
                    }
                }
            }
        }
    }

    /// The children given up (over their restart limit, or failing every start), by name.
    pub fn given_up(&self) -> Vec<String> {
        self.children
            .iter()
            .filter(|m| m.given_up)
            .map(|m| m.spec.name.clone())
            .collect()
    }

    /// Restarts of every child so far.
    pub fn restarts(&self) -> u64 {
        self.children.iter().map(|m| m.restarts).sum()
    }

    /// (name, pid) of every running child.
    pub fn running(&self) -> Vec<(String, u32)> {
        self.children
            .iter()
            .filter_map(|m| m.child.as_ref().map(|c| (m.spec.name.clone(), c.id())))
            .collect()
    }

    /// SIGKILL to the child running as `pid` (a hung one); [`Supervisor::poll`] then reaps and
    /// restarts it as after any exit. False when no child runs as `pid`.
    pub fn kill(&mut self, pid: u32) -> bool {
        let Some(child) = self
            .children
            .iter_mut()
            .filter_map(|m| m.child.as_mut())
            .find(|c| c.id() == pid)
        else {
            return false;
        };
        child.kill().is_ok()
    }

    /// The pid of the running child `name` (no allocation: the supervision loop asks often).
    pub fn running_pid(&self, name: &str) -> Option<u32> {
        self.children
            .iter()
            .find(|m| m.spec.name == name)
            .and_then(|m| m.child.as_ref().map(Child::id))
    }

    /// Every supervised child: name, current pid (`None` while waiting to restart), restarts.
    pub fn children(&self) -> Vec<ChildStatus> {
        self.children
            .iter()
            .map(|m| ChildStatus {
                name: m.spec.name.clone(),
                pid: m.child.as_ref().map(Child::id),
                restarts: m.restarts,
                given_up: m.given_up,
            })
            .collect()
    }

    /// Samples the CPU time and peak memory of every running child and of this process, at most
    /// once per [`crate::process_usage::SAMPLE_PERIOD`].
    pub fn sample_usage_if_due(&mut self, now: Instant) {
        self.usage.sample_if_due(now, processes(&self.children));
    }

    /// CPU time and peak memory per process over `elapsed` (the run), this process as `watchdog`.
    pub fn usage(&self, elapsed: Duration) -> Vec<ProcessUsage> {
        self.usage.totals(ticks_per_second(), elapsed)
    }

    /// SIGTERM to every child, in reverse start order, the `stops_last` children after the others
    /// have gone; SIGKILL to those still running after `grace` (each phase has its own grace).
    pub fn stop_all(&mut self, grace: Duration) {
        // The last reading of each child, while it still runs.
        self.usage.sample(processes(&self.children));
        self.stop_where(grace, |spec| !spec.stops_last);
        self.stop_where(grace, |_| true);
    }

    fn stop_where(&mut self, grace: Duration, selected: impl Fn(&ChildSpec) -> bool) {
        for m in self.children.iter().rev().filter(|m| selected(&m.spec)) {
            if let Some(child) = &m.child {
                // SAFETY: plain kill(2) on a pid we own and have not reaped yet.
                unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
            }
        }
        let deadline = Instant::now() + grace;
        loop {
            let mut running = 0;
            for m in self.children.iter_mut().filter(|m| selected(&m.spec)) {
                if let Some(child) = &mut m.child {
                    match child.try_wait() {
                        Ok(Some(_)) | Err(_) => m.child = None,
                        Ok(None) => running += 1,
                    }
                }
            }
            if running == 0 {
                return;
            }
            if Instant::now() >= deadline {
                break;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        for m in self.children.iter_mut().filter(|m| selected(&m.spec)) {
            if let Some(mut child) = m.child.take() {
                tracing::warn!(child = %m.spec.name, "did not stop in time; killing");
                let _ = child.kill();
                let _ = child.wait();
            }
        }
    }
}
