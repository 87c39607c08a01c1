//! `rins status [--json] [--timeout S]`: the watchdog's latest health report as a table (or one
//! JSON object): per process its state, pid, restarts, heartbeat age and output rate; the
//! navigation mode, lane and aiding; every redundant channel with its state and reason, and the
//! parity test statistics; and the deployment profile `rins up` chose, with why.

use std::time::{Duration, Instant};

use anyhow::{Result, bail};
use ipc_types::{HealthReport, names};
use rins::deploy_profile_file::{self, ProfileRecord};
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::payload::OtherVersionWarning;
use rins_runtime::setup_guard::SetupGuard;
use rins_runtime::tool_node::ToolNode;
use rins_watchdog::gnss_line;
use rins_watchdog::redundancy_view::{RedundancyView, SensorRow};
pub use rins_watchdog::status_rows::{StatusReport, rows};
use serde::Serialize;

use super::status_link;

pub fn table(report: &StatusReport) -> String {
    let mut out = format!("up {:.1} s\n", report.uptime_s);
    out.push_str("service            state       pid      restarts  heartbeat  output\n");
    for r in &report.services {
        let age = r
            .heartbeat_age_ms
            .map_or_else(|| "-".to_string(), |a| format!("{a} ms"));
        let rate = r
            .output_rate_hz
            .map_or_else(|| "-".to_string(), |h| format!("{h:.0}/s"));
        let stale = if r.input_stale { "  input stale" } else { "" };
        out.push_str(&format!(
            "{:<18} {:<11} {:<8} {:<9} {:<10} {rate}{stale}\n",
            r.service, r.state, r.pid, r.restarts, age
        ));
    }
    match &report.navigation {
        // Its mode and integrity were the last sample's: nothing to show of a stopped output.
        Some(n) if !n.output_flowing => out.push_str(&format!("\nnavigation   {}\n", n.summary)),
        Some(n) => {
            out.push_str(&format!(
                "\nnavigation   {}, integrity {}",
                n.summary, n.integrity
            ));
            if !n.integrity_reasons.is_empty() {
                out.push_str(&format!(" ({})", n.integrity_reasons.join(",")));
            }
            out.push('\n');
        }
        None => out.push_str("\nnavigation   no output yet\n"),
    }
    match &report.redundancy {
        Some(r) => out.push_str(&channel_table(r)),
        None => out.push_str("redundancy   no fused output yet\n"),
    }
    out.push_str(&status_link::link_line(report.link.as_ref()));
    out.push_str(&gnss_line::gnss_lines(report.gnss.as_ref()));
    out
}

/// The report with the deployment's profile: in the JSON, `profile` and `profile_reason` beside the
/// report's own fields; in the table, a line above it.
#[derive(Serialize)]
struct WithProfile<'a> {
    #[serde(flatten)]
    report: &'a StatusReport,
    #[serde(flatten)]
    profile: &'a ProfileRecord,
}

fn table_with_profile(w: &WithProfile<'_>) -> String {
    let mut out = w.profile.line();
    out.push_str(&table(w.report));
    out
}

/// The redundancy part of the table: the summary, every channel with its state and reason, and
/// the parity test statistic of each type.
fn channel_table(r: &RedundancyView) -> String {
    let mut out = format!("redundancy   {}\n", r.summary);
    if !r.flags.is_empty() {
        out.push_str(&format!("fused flags  {}\n", r.flags.join(",")));
    }
    out.push_str("channel      state       reason\n");
    for c in &r.channels {
        out.push_str(&format!(
            "{:<12} {:<11} {}\n",
            c.channel,
            c.state,
            c.reason.as_deref().unwrap_or("-")
        ));
    }
    // Three channels leave no parity space: no statistic to show.
    let statistic = |row: &SensorRow| {
        if row.in_use > 3 {
            format!("{:.2}", row.test_statistic)
        } else {
            "- (no parity with 3 channels)".to_string()
        }
    };
    out.push_str(&format!(
        "parity test  gyro {}  accel {}\n",
        statistic(&r.gyro),
        statistic(&r.accel)
    ));
    out
}

pub fn run(json: bool, timeout_s: f64) -> Result<()> {
    if !(timeout_s.is_finite() && timeout_s > 0.0) {
        bail!("--timeout {timeout_s}: must be a positive number of seconds");
    }
    // Joining and subscribing keep the timeout whatever the deployment's files hold (iceoryx2
    // waits for ever on some damaged ones).
    let guard = SetupGuard::arm(
        "status: subscribing to the health report".into(),
        Some(Duration::from_secs_f64(timeout_s)),
        None,
    );
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("status")?;
    let (node, settings) = (tool.node(), tool.settings());
    let sub = TopicSubscriber::<HealthReport>::new(node, names::HEALTH)?;
    guard.disarm();
    let deadline = Instant::now() + Duration::from_secs_f64(timeout_s);
    let mut version_warning = OtherVersionWarning::new();
    let report = loop {
        sub.wait(Duration::from_millis(50))?;
        let mut latest = None;
        while let Some(r) = sub.receive()? {
            latest = Some(r);
        }
        version_warning.check("status", sub.rejected());
        if let Some(r) = latest {
            break r;
        }
        if Instant::now() >= deadline && sub.rejected() > 0 {
            bail!(
                "no health report of payload version {} within {timeout_s} s: {} of another \
                 version dropped (is the pipeline on RINS_IPC_PREFIX {} of another build?)",
                ipc_types::PAYLOAD_VERSION,
                sub.rejected(),
                settings.prefix
            );
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
    // The file of this same deployment: the run directory of the settings joined.
    let profile = deploy_profile_file::read(settings);
    let out = WithProfile {
        report: &report,
        profile: &profile,
    };
    super::report_out::print_report(json, &out, table_with_profile)
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::{ServiceHealth, ServiceKind, ServiceState};

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
        assert!(r.navigation.is_none() && r.redundancy.is_none());
        assert!(
            t.contains("navigation   no output yet") && t.contains("no fused output yet"),
            "{t}"
        );
    }

    #[test]
    fn the_table_lists_every_channel_with_its_state_and_reason() {
        use ipc_types::{ChannelState, FaultReason, FusedImu, NavMode, NavState};
        use rins_watchdog::redundancy_view::{nav_of, redundancy_of};
        let mut fused = FusedImu {
            n_gyro: 4,
            n_accel: 4,
            gyro_test_statistic: 2.5,
            ..FusedImu::default()
        };
        fused.gyro_state[..4].fill(ChannelState::Ok as u8);
        fused.accel_state[..4].fill(ChannelState::Ok as u8);
        fused.gyro_state[1] = ChannelState::Excluded as u8;
        fused.gyro_reason[1] = FaultReason::Parity as u8;
        let report = HealthReport {
            redundancy: redundancy_of(&fused, 5),
            nav: nav_of(
                &NavState {
                    mode: NavMode::Navigating as u8,
                    lane: 1,
                    ..NavState::default()
                },
                5,
            ),
            ..HealthReport::default()
        };
        let r = rows(&report);
        let t = table(&r);
        assert!(
            t.contains("redundancy   gyro 3/4 (gyro1 parity) accel 4/4"),
            "{t}"
        );
        assert!(
            t.contains("navigation   navigating, lane 1, integrity ok"),
            "{t}"
        );
        assert_eq!(t.matches("\ngyro").count(), 4, "{t}");
        assert_eq!(t.matches("\naccel").count(), 4, "{t}");
        assert!(t.contains("gyro1        excluded    parity"), "{t}");
        assert!(
            t.contains("parity test  gyro - (no parity with 3 channels)  accel 0.00"),
            "{t}"
        );
        let json: serde_json::Value =
            serde_json::from_str(&serde_json::to_string(&r).expect("serialises")).expect("json");
        assert_eq!(json["redundancy"]["gyro"]["in_use"], 3);
        assert_eq!(json["redundancy"]["channels"][1]["reason"], "parity");
        assert_eq!(json["navigation"]["lane"], 1);
        assert_eq!(json["navigation"]["output_flowing"], true);
    }

    /// The profile leads the table and sits beside the report's fields in the JSON.
    #[test]
    fn the_profile_is_printed_with_the_report() {
        let r = rows(&HealthReport::default());
        let profile = ProfileRecord {
            profile: "shared".into(),
            profile_reason: "auto: 2 usable CPUs, 2 free; dedicated needs 4: shared".into(),
        };
        let w = WithProfile {
            report: &r,
            profile: &profile,
        };
        let t = table_with_profile(&w);
        assert!(
            t.starts_with(
                "profile: shared — auto: 2 usable CPUs, 2 free; dedicated needs 4: shared\nup "
            ),
            "{t}"
        );
        let json = serde_json::to_value(&w).expect("serialises");
        assert_eq!(json["profile"], "shared");
        assert_eq!(json["profile_reason"], profile.profile_reason.as_str());
        assert!(json["services"].is_array(), "{json}");
    }

    /// A report whose navigation sample is old says the output stopped, in the table and the
    /// JSON, and nowhere "navigating".
    #[test]
    fn a_stopped_navigation_output_is_not_reported_as_navigating() {
        use ipc_types::{NavMode, NavState};
        use rins_watchdog::redundancy_view::nav_of;
        let report = HealthReport {
            nav: nav_of(
                &NavState {
                    mode: NavMode::Navigating as u8,
                    ..NavState::default()
                },
                12_345,
            ),
            ..HealthReport::default()
        };
        let r = rows(&report);
        let t = table(&r);
        assert!(
            t.contains("navigation   no navigation output for 12.3 s\n"),
            "{t}"
        );
        assert!(!t.contains("navigating"), "{t}");
        let json: serde_json::Value =
            serde_json::from_str(&serde_json::to_string(&r).expect("serialises")).expect("json");
        assert_eq!(json["navigation"]["mode"], "invalid");
        assert_eq!(json["navigation"]["output_flowing"], false);
    }
}
