//! The watchdog's reasons to kill a child that still runs: heartbeat overdue, output overdue while
//! its input arrives, iceoryx2 node found dead. A killed child is reaped and restarted by the
//! supervisor like any child that exited.

use std::time::Instant;

use ipc_types::{HealthReport, ServiceKind, ServiceState};
use rins_runtime::error_chain::ErrorChain;
use rins_runtime::ipc::IpcSettings;

use crate::monitor::Monitor;
use crate::output_deadline::OutputDeadline;
use crate::supervisor::Supervisor;

/// Stages judged by their output deadline: each reads a topic the monitor counts.
const DEADLINED: [ServiceKind; 4] = [
    ServiceKind::Fusion,
    ServiceKind::Altimeter,
    ServiceKind::Navigator,
    ServiceKind::NavigatorStandby,
];

/// SIGKILL to every process the report calls silent (heartbeat overdue while it still runs: hung or
/// stopped); the supervisor restarts it like any process that exited.
pub fn kill_hung(report: &HealthReport, supervisor: &mut Supervisor) {
    let count = usize::from(report.count).min(report.services.len());
    for s in &report.services[..count] {
        let silent = ServiceState::from_u8(s.state) == Some(ServiceState::Silent);
        let own = s.pid == std::process::id();
        if silent && !own && supervisor.kill(s.pid) {
            tracing::warn!(
                service = ServiceKind::from_u8(s.service).map_or("?", |k| k.name()),
                pid = s.pid,
                heartbeat_age_ms = s.heartbeat_age_ms,
                "heartbeat overdue: killed, will be restarted"
            );
        }
    }
}

/// A hung stage is seen sooner by its output than by its heartbeat: input arriving, output silent
/// for `[watchdog] output_deadline_s`. It is killed, so that it is reaped and restarted like any
/// exit.
pub fn kill_overdue_outputs(
    deadline: &mut OutputDeadline,
    monitor: &Monitor,
    supervisor: &mut Supervisor,
    now: Instant,
) {
    for kind in DEADLINED {
        let (Some(pid), Some(input), Some(output)) = (
            supervisor.running_pid(kind.name()),
            monitor.input_count(kind),
            monitor.output_count(kind),
        ) else {
            continue;
        };
        if deadline.observe(kind, pid, input, output, now) && supervisor.kill(pid) {
            tracing::warn!(
                service = kind.name(),
                pid,
                "output overdue while its input arrives: killed, will be restarted"
            );
        }
    }
}

/// Another way a death is seen, besides the child's exit, its heartbeat and its output deadline:
/// iceoryx2 finds its node dead. Every dead node's resources are freed; a child the supervisor
/// still counts as running under that pid is killed, so that it is reaped and restarted like any
/// exit.
pub fn sweep_dead_nodes(settings: &IpcSettings, supervisor: &mut Supervisor) {
    let result = rins_runtime::ipc::for_each_dead_node(settings, |name, pid| {
        let child = pid.filter(|&p| supervisor.kill(p));
        match child {
            Some(pid) => {
                tracing::warn!(
                    node = name,
                    pid,
                    "iceoryx2 node dead: killed, will be restarted"
                )
            }
            None => tracing::info!(node = name, ?pid, "removed the resources of a dead node"),
        }
    });
    if let Err(e) = result {
        tracing::warn!(error = %ErrorChain(&e), "cannot sweep dead nodes");
    }
}
