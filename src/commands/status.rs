//! `rins status [--json] [--timeout S]`: the watchdog's latest health report as a table (or one
//! JSON object): per process its state, pid, restarts, heartbeat age and output rate.

use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use ipc_types::{HealthReport, ServiceKind, ServiceState, names};
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::tool_node::ToolNode;
use serde::Serialize;

/// One process as printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ServiceRow {
    pub service: String,
    pub state: String,
    pub pid: u32,
    pub restarts: u32,
    /// Its last heartbeat said its input is quiet.
    pub input_stale: bool,
    /// `None` before the first heartbeat.
    pub heartbeat_age_ms: Option<u32>,
    /// `None` for a process without an output topic.
    pub output_rate_hz: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StatusReport {
    pub uptime_s: f64,
    pub services: Vec<ServiceRow>,
}

/// The printable form of a report; entries with unknown codes are named by their number.
pub fn rows(report: &HealthReport) -> StatusReport {
    let count = usize::from(report.count).min(report.services.len());
    let services = report.services[..count]
        .iter()
        .map(|s| ServiceRow {
            service: ServiceKind::from_u8(s.service)
                .map_or_else(|| format!("service {}", s.service), |k| k.name().into()),
            state: ServiceState::from_u8(s.state)
                .map_or_else(|| format!("state {}", s.state), |k| k.name().into()),
            pid: s.pid,
            restarts: s.restarts,
            input_stale: s.input_stale != 0,
            heartbeat_age_ms: (s.heartbeat_age_ms != u32::MAX).then_some(s.heartbeat_age_ms),
            output_rate_hz: s
                .output_rate_hz
                .is_finite()
                .then_some(f64::from(s.output_rate_hz)),
        })
        .collect();
    StatusReport {
        uptime_s: report.uptime_ms as f64 * 1e-3,
        services,
    }
}

pub fn table(report: &StatusReport) -> String {
    let mut out = format!("up {:.1} s\n", report.uptime_s);
    out.push_str("service      state       pid      restarts  heartbeat  output\n");
    for r in &report.services {
        let age = r
            .heartbeat_age_ms
            .map_or_else(|| "-".to_string(), |a| format!("{a} ms"));
        let rate = r
            .output_rate_hz
            .map_or_else(|| "-".to_string(), |h| format!("{h:.0}/s"));
        let stale = if r.input_stale { "  input stale" } else { "" };
        out.push_str(&format!(
            "{:<12} {:<11} {:<8} {:<9} {:<10} {rate}{stale}\n",
            r.service, r.state, r.pid, r.restarts, age
        ));
    }
    out
}

pub fn run(json: bool, timeout_s: f64) -> Result<()> {
    if !(timeout_s.is_finite() && timeout_s > 0.0) {
        bail!("--timeout {timeout_s}: must be a positive number of seconds");
    }
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("status")?;
    let (node, settings) = (tool.node(), tool.settings());
    let sub = TopicSubscriber::<HealthReport>::new(node, names::HEALTH)?;
    let deadline = Instant::now() + Duration::from_secs_f64(timeout_s);
    let report = loop {
        sub.wait(Duration::from_millis(50))?;
        let mut latest = None;
        while let Some(r) = sub.receive()? {
            latest = Some(r);
        }
        if let Some(r) = latest {
            break r;
        }
        if Instant::now() >= deadline {
            bail!(
                "no health report within {timeout_s} s: is the pipeline running (`rins up`) with \
                 the same RINS_IPC_PREFIX ({})?",
                settings.prefix
            );
        }
    };
    let report = rows(&report);
    if json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{}", table(&report));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::ServiceHealth;

    #[test]
    fn rows_name_services_and_states_and_leave_unknowns_as_none() {
        let mut report = HealthReport {
            count: 2,
            uptime_ms: 1500,
            ..HealthReport::default()
        };
        report.services[0] = ServiceHealth {
            service: ServiceKind::Navigator as u8,
            state: ServiceState::Running as u8,
            pid: 42,
            restarts: 1,
            heartbeat_age_ms: 120,
            output_rate_hz: 1000.0,
            ..ServiceHealth::default()
        };
        report.services[1] = ServiceHealth {
            service: ServiceKind::Simulator as u8,
            state: ServiceState::Starting as u8,
            heartbeat_age_ms: u32::MAX,
            output_rate_hz: f32::NAN,
            ..ServiceHealth::default()
        };
        let r = rows(&report);
        assert_eq!(r.uptime_s, 1.5);
        assert_eq!(r.services.len(), 2);
        assert_eq!(r.services[0].service, "navigator");
        assert_eq!(r.services[0].state, "running");
        assert_eq!(r.services[0].heartbeat_age_ms, Some(120));
        assert_eq!(r.services[0].output_rate_hz, Some(1000.0));
        assert_eq!(r.services[1].heartbeat_age_ms, None);
        assert_eq!(r.services[1].output_rate_hz, None);
        let t = table(&r);
        assert!(
            t.contains("navigator") && t.contains("1000/s") && t.contains("120 ms"),
            "{t}"
        );
    }
}
