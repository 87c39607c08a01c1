//! Publishes the [`HealthReport`] a few times a second from the supervisor's children and the
//! monitor's heartbeats and topic counts.

use std::time::{Duration, Instant};

use anyhow::Result;
use ipc_types::{HealthReport, ServiceKind, names};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::ipc::{IpcNode, TopicPublisher};

use crate::health_report::{ProcessView, build_report};
use crate::monitor::{HeartbeatSeen, Monitor, link_report};
use crate::supervisor::Supervisor;

/// Report period.
pub const PERIOD: Duration = Duration::from_millis(250);

/// Publishes the deployment's health report, once a second.
pub struct HealthPublisher {
    publisher: TopicPublisher<HealthReport>,
    /// A running process whose heartbeat is older than this is reported silent.
    silent_after: Duration,
    started: Instant,
    next_due: Instant,
    last_at: Instant,
    /// Output counts per [`ServiceKind`] at the previous report.
    last_outputs: [u64; ServiceKind::ALL.len()],
}

impl HealthPublisher {
    /// The publisher on `node`; a process whose heartbeat is older than `silent_after` is reported silent.
    pub fn new(node: &IpcNode, started: Instant, silent_after: Duration) -> Result<Self> {
        let now = Instant::now();
        Ok(Self {
            publisher: TopicPublisher::new(node, names::HEALTH)?,
            silent_after,
            started,
            next_due: now,
            last_at: now,
            last_outputs: [0; ServiceKind::ALL.len()],
        })
    }

    /// Publishes a report when one is due, and returns it.
    pub fn tick(
        &mut self,
        supervisor: &Supervisor,
        monitor: &Monitor,
    ) -> Result<Option<HealthReport>> {
        let now = Instant::now();
        if now < self.next_due {
            return Ok(None);
        }
        self.next_due = now + PERIOD;
        let dt = now.duration_since(self.last_at).as_secs_f64().max(1e-3);
        self.last_at = now;
        let me = std::process::id();
        let watchdog = ProcessView {
            kind: ServiceKind::Watchdog,
            pid: Some(me),
            given_up: false,
            restarts: 0,
            heartbeat: Some(HeartbeatSeen {
                pid: me,
                at_ns: monotonic_ns(),
                input_stale: false,
            }),
            output_rate_hz: f64::NAN,
        };
        let views: Vec<ProcessView> = std::iter::once(watchdog)
            .chain(supervisor.children().into_iter().filter_map(|child| {
                let kind = ServiceKind::from_name(&child.name)?;
                let output_rate_hz = monitor.output_count(kind).map_or(f64::NAN, |n| {
                    n.saturating_sub(self.last_outputs[kind as usize]) as f64 / dt
                });
                Some(ProcessView {
                    kind,
                    pid: child.pid,
                    given_up: child.given_up,
                    restarts: child.restarts,
                    heartbeat: monitor.heartbeats[kind as usize],
                    output_rate_hz,
                })
            }))
            .collect();
        for kind in ServiceKind::ALL {
            if let Some(n) = monitor.output_count(kind) {
                self.last_outputs[kind as usize] = n;
            }
        }
        let now_ns = monotonic_ns();
        let mut report = build_report(
            now_ns,
            self.started.elapsed().as_millis() as u64,
            &views,
            u64::try_from(self.silent_after.as_nanos()).unwrap_or(u64::MAX),
        );
        report.redundancy = monitor.redundancy_report(now_ns);
        report.nav = monitor.nav_report(now_ns);
        report.link = link_report(monitor);
        report.gnss = monitor.last_gnss_link;
        self.publisher.publish(report)?;
        Ok(Some(report))
    }
}
