//! The watchdog's health report as a `diagnostic_msgs/msg/DiagnosticArray`: one status per
//! supervised process, then the navigation, the redundant channels, the serial line and (when
//! fitted) the GNSS receiver, each with the figures `rins status --json` prints as key/value text.

use ipc_types::HealthReport;
use rins_ros2_messages::messages::{Header, Time};
use rins_ros2_messages::{DiagnosticArray, DiagnosticStatus, KeyValue};
use rins_watchdog::status_rows::{ServiceRow, rows};
use serde_json::Value;

/// `value` flattened into `a.b` keys, arrays of plain values joined by `,`.
fn flatten(prefix: &str, value: &Value, out: &mut Vec<KeyValue>) {
    let key = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                flatten(&key(k), v, out);
            }
        }
        Value::Array(items) if items.iter().all(|v| !v.is_object() && !v.is_array()) => {
            let text: Vec<String> = items.iter().map(plain).collect();
            out.push(KeyValue {
                key: prefix.to_string(),
                value: text.join(","),
            });
        }
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                flatten(&key(&i.to_string()), v, out);
            }
        }
        other => out.push(KeyValue {
            key: prefix.to_string(),
            value: plain(other),
        }),
    }
}

/// A plain JSON value as text, strings without their quotes.
fn plain(v: &Value) -> String {
    v.as_str().map_or_else(|| v.to_string(), str::to_string)
}

fn values_of<T: serde::Serialize>(part: &T) -> Vec<KeyValue> {
    let mut out = Vec::new();
    if let Ok(v) = serde_json::to_value(part) {
        flatten("", &v, &mut out);
    }
    out
}

fn status(level: u8, name: &str, message: String, values: Vec<KeyValue>) -> DiagnosticStatus {
    DiagnosticStatus {
        level,
        name: format!("rins: {name}"),
        message,
        hardware_id: "rins".into(),
        values,
    }
}

/// A process's level: running is OK (WARN with its input quiet), starting or restarting WARN,
/// silent or given up ERROR.
fn service_level(row: &ServiceRow) -> u8 {
    match row.state.as_str() {
        "running" if row.input_stale => DiagnosticStatus::WARN,
        "running" => DiagnosticStatus::OK,
        "starting" | "restarting" => DiagnosticStatus::WARN,
        _ => DiagnosticStatus::ERROR,
    }
}

/// The array of `report`, stamped `stamp_ns` (system time).
pub fn diagnostic_array(report: &HealthReport, stamp_ns: u64) -> DiagnosticArray {
    let r = rows(report);
    let mut status_list: Vec<DiagnosticStatus> = r
        .services
        .iter()
        .map(|s| {
            let mut values = values_of(s);
            // The watchdog's row also says how long the deployment has been up.
            if s.service == "watchdog" {
                values.push(KeyValue {
                    key: "uptime_s".into(),
                    value: format!("{:.3}", r.uptime_s),
                });
            }
            status(service_level(s), &s.service, s.state.clone(), values)
        })
        .collect();
    let stale = |name: &str, what: &str| {
        status(DiagnosticStatus::STALE, name, what.to_string(), Vec::new())
    };
    status_list.push(match &r.navigation {
        Some(n) => {
            let level = match n.integrity.as_str() {
                _ if !n.output_flowing => DiagnosticStatus::ERROR,
                "ok" => DiagnosticStatus::OK,
                "degraded" => DiagnosticStatus::WARN,
                _ => DiagnosticStatus::ERROR,
            };
            status(level, "navigation", n.summary.clone(), values_of(n))
        }
        None => stale("navigation", "no output yet"),
    });
    status_list.push(match &r.redundancy {
        Some(red) => {
            let level = if red.flags.is_empty() {
                DiagnosticStatus::OK
            } else {
                DiagnosticStatus::WARN
            };
            status(level, "redundancy", red.summary.clone(), values_of(red))
        }
        None => stale("redundancy", "no fused output yet"),
    });
    status_list.push(match &r.link {
        Some(link) => status(
            DiagnosticStatus::OK,
            "serial link",
            "heard".into(),
            values_of(link),
        ),
        None => stale("serial link", "not heard from acquisition yet"),
    });
    if let Some(g) = &r.gnss {
        status_list.push(status(
            DiagnosticStatus::OK,
            "gnss",
            "heard".into(),
            values_of(g),
        ));
    }
    DiagnosticArray {
        header: Header {
            stamp: Time::from_ns(stamp_ns),
            frame_id: String::new(),
        },
        status: status_list,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::{ServiceKind, ServiceState};

    #[test]
    fn each_process_and_part_has_a_status_with_its_level() {
        let mut report = HealthReport {
            count: 2,
            uptime_ms: 1500,
            ..HealthReport::default()
        };
        report.services[0].service = ServiceKind::Fusion as u8;
        report.services[0].state = ServiceState::Running as u8;
        report.services[0].pid = 42;
        report.services[0].output_rate_hz = 1000.0;
        report.services[1].service = ServiceKind::Navigator as u8;
        report.services[1].state = ServiceState::GivenUp as u8;
        let a = diagnostic_array(&report, 7_000_000_001);
        assert_eq!(a.header.stamp, Time { sec: 7, nanosec: 1 });
        let names: Vec<&str> = a.status.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "rins: fusion",
                "rins: navigator",
                "rins: navigation",
                "rins: redundancy",
                "rins: serial link",
            ]
        );
        let levels: Vec<u8> = a.status.iter().map(|s| s.level).collect();
        assert_eq!(levels, [0, 2, 3, 3, 3]);
        let pid = a.status[0].values.iter().find(|kv| kv.key == "pid");
        assert_eq!(pid.map(|kv| kv.value.as_str()), Some("42"));
        assert_eq!(a.status[1].message, "given-up");
    }
}
