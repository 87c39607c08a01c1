//! The watchdog's health report in its printable form, for `rins status` and for whatever carries
//! it beyond the host: per process its state, pid, restarts, heartbeat age and output rate; the
//! navigation, the redundant channels, the serial line and the GNSS receiver's line.

use ipc_types::{HealthReport, LinkReport, ServiceKind, ServiceState};
use serde::Serialize;
use serde::ser::{SerializeStruct, Serializer};

use crate::gnss_line::{self, GnssRow};
use crate::link::link_error_name;
use crate::redundancy_view::{NavView, RedundancyView, nav_view, redundancy_view};

/// One process as printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ServiceRow {
    /// The process's service name.
    pub service: String,
    /// Its state by name.
    pub state: String,
    /// Its process id (0 while restarting).
    pub pid: u32,
    /// Restarts since the watchdog started.
    pub restarts: u32,
    /// Its last heartbeat said its input is quiet.
    pub input_stale: bool,
    /// `None` before the first heartbeat.
    pub heartbeat_age_ms: Option<u32>,
    /// `None` for a process without an output topic.
    pub output_rate_hz: Option<f64>,
}

/// The whole report as printed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StatusReport {
    /// Time since the watchdog started.
    pub uptime_s: f64,
    /// Every supervised process.
    pub services: Vec<ServiceRow>,
    /// `None` before the first navigation sample.
    pub navigation: Option<NavView>,
    /// `None` before the first fused sample.
    pub redundancy: Option<RedundancyView>,
    /// `None` before acquisition's first heartbeat.
    pub link: Option<LinkRow>,
    /// `None` without a gnss service, or before its first report.
    pub gnss: Option<GnssRow>,
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
        navigation: nav_view(&report.nav),
        redundancy: redundancy_view(&report.redundancy),
        link: link_row(&report.link),
        gnss: gnss_line::gnss_row(&report.gnss),
    }
}

/// The serial line as printed (`link` in the JSON): the report's counters, the last decode error
/// by name (`none`, `no-sync`, `crc-mismatch`, ...), without the layout's own fields.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkRow(pub LinkReport);

impl Serialize for LinkRow {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let l = &self.0;
        let mut row = s.serialize_struct("LinkRow", 7)?;
        row.serialize_field("bytes_received", &l.bytes_received)?;
        row.serialize_field("valid_frames", &l.valid_frames)?;
        row.serialize_field("discarded_bytes", &l.discarded_bytes)?;
        row.serialize_field("crc_errors", &l.crc_errors)?;
        row.serialize_field("malformed", &l.malformed)?;
        row.serialize_field("reconnects", &l.reconnects)?;
        row.serialize_field("last_decode_error", &link_error_name(l.last_decode_error))?;
        row.end()
    }
}

/// The printable link of a report; `None` while acquisition has not been heard.
pub fn link_row(link: &LinkReport) -> Option<LinkRow> {
    (link.heard != 0).then_some(LinkRow(*link))
}
