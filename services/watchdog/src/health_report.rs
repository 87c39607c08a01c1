//! The watchdog's health report: per supervised process its state, pid, restarts, heartbeat age
//! and output rate, built from what the supervisor and the monitor know.

use ipc_types::{
    HealthReport, MAX_SUPERVISED, PAYLOAD_VERSION, ServiceHealth, ServiceKind, ServiceState,
};

use crate::monitor::HeartbeatSeen;

/// What is known of one process when the report is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProcessView {
    /// Which process.
    pub kind: ServiceKind,
    /// Current pid; `None` while it waits out its restart backoff or was given up.
    pub pid: Option<u32>,
    /// Exceeded its restart limit: no longer restarted.
    pub given_up: bool,
    /// Times it was restarted.
    pub restarts: u64,
    /// The last heartbeat of this kind of process.
    pub heartbeat: Option<HeartbeatSeen>,
    /// Samples per second on its output topic (NaN when it has none).
    pub output_rate_hz: f64,
}

/// The state of one process. A heartbeat counts only when it came from the current pid: after a
/// restart the previous incarnation's heartbeat says nothing about the new one.
pub fn state_of(view: &ProcessView, now_ns: u64, silent_after_ns: u64) -> (ServiceState, u32) {
    let Some(pid) = view.pid else {
        let state = if view.given_up {
            ServiceState::GivenUp
        } else {
            ServiceState::Restarting
        };
        return (state, u32::MAX);
    };
    match view.heartbeat {
        Some(h) if h.pid == pid => {
            let age_ns = now_ns.saturating_sub(h.at_ns);
            let age_ms = u32::try_from(age_ns / 1_000_000).unwrap_or(u32::MAX - 1);
            let state = if age_ns > silent_after_ns {
                ServiceState::Silent
            } else {
                ServiceState::Running
            };
            (state, age_ms)
        }
        _ => (ServiceState::Starting, u32::MAX),
    }
}

/// The report for `views` (at most [`MAX_SUPERVISED`]; the rest are left out).
pub fn build_report(
    now_ns: u64,
    uptime_ms: u64,
    views: &[ProcessView],
    silent_after_ns: u64,
) -> HealthReport {
    let mut report = HealthReport {
        version: PAYLOAD_VERSION,
        now_ns,
        uptime_ms,
        ..HealthReport::default()
    };
    for (slot, view) in report.services.iter_mut().zip(views) {
        let (state, heartbeat_age_ms) = state_of(view, now_ns, silent_after_ns);
        let own_heartbeat = view.heartbeat.filter(|h| Some(h.pid) == view.pid);
        *slot = ServiceHealth {
            service: view.kind as u8,
            state: state as u8,
            input_stale: u8::from(own_heartbeat.is_some_and(|h| h.input_stale)),
            pid: view.pid.unwrap_or(0),
            restarts: u32::try_from(view.restarts).unwrap_or(u32::MAX),
            heartbeat_age_ms,
            output_rate_hz: view.output_rate_hz as f32,
            ..ServiceHealth::default()
        };
    }
    report.count = views.len().min(MAX_SUPERVISED) as u8;
    report
}

#[cfg(test)]
mod tests {
    use super::*;

    const SILENT_NS: u64 = 3_000_000_000;

    fn view(pid: Option<u32>, heartbeat: Option<(u32, u64)>) -> ProcessView {
        ProcessView {
            kind: ServiceKind::Fusion,
            pid,
            given_up: false,
            restarts: 2,
            heartbeat: heartbeat.map(|(pid, at_ns)| HeartbeatSeen {
                pid,
                at_ns,
                input_stale: true,
            }),
            output_rate_hz: 1000.0,
        }
    }

    #[test]
    fn states_follow_pid_heartbeat_and_age() {
        let now = 10_000_000_000;
        assert_eq!(
            state_of(&view(None, Some((7, now))), now, SILENT_NS),
            (ServiceState::Restarting, u32::MAX)
        );
        let given_up = ProcessView {
            given_up: true,
            ..view(None, None)
        };
        assert_eq!(
            state_of(&given_up, now, SILENT_NS),
            (ServiceState::GivenUp, u32::MAX)
        );
        // A heartbeat from the previous incarnation does not count.
        assert_eq!(
            state_of(&view(Some(8), Some((7, now))), now, SILENT_NS),
            (ServiceState::Starting, u32::MAX)
        );
        assert_eq!(
            state_of(&view(Some(8), Some((8, now - 250_000_000))), now, SILENT_NS),
            (ServiceState::Running, 250)
        );
        assert_eq!(
            state_of(
                &view(Some(8), Some((8, now - 4_000_000_000))),
                now,
                SILENT_NS
            ),
            (ServiceState::Silent, 4000)
        );
    }

    #[test]
    fn report_holds_every_process_up_to_the_capacity() {
        let views = vec![view(Some(8), Some((8, 5))); MAX_SUPERVISED + 2];
        let r = build_report(5, 1234, &views, SILENT_NS);
        assert_eq!(r.count as usize, MAX_SUPERVISED);
        assert_eq!(r.uptime_ms, 1234);
        let s = r.services[0];
        assert_eq!(ServiceKind::from_u8(s.service), Some(ServiceKind::Fusion));
        assert_eq!(ServiceState::from_u8(s.state), Some(ServiceState::Running));
        assert_eq!((s.pid, s.restarts, s.heartbeat_age_ms), (8, 2, 0));
        assert_eq!(s.input_stale, 1);
        // A stale flag from a previous incarnation is not carried over.
        let r = build_report(5, 0, &[view(Some(9), Some((8, 5)))], SILENT_NS);
        assert_eq!(r.services[0].input_stale, 0);
        assert_eq!(s.output_rate_hz, 1000.0);
    }
}
