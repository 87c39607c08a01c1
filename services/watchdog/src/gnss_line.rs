//! The GNSS receiver's line as the gnss service last reported it, for `rins status` and the run
//! summary: every counter by name, and a warning while the line carries bytes but nothing usable.

use ipc_types::GnssLinkReport;
use serde::ser::{Serialize, Serializer};
use serde_json::Value;

/// The layout's own fields, not counters: left out of the printed row.
const LAYOUT_FIELDS: [&str; 4] = ["version", "heard", "_pad", "now_ns"];

/// What the operator is told while the line is silent.
pub const SILENT_WARNING: &str = "the line carries bytes but no usable sentence or frame: check \
     the receiver's baud rate and protocol (`rins probe --port DEVICE --gnss` listens to it)";

/// The GNSS line as printed (`gnss` in the JSON): every counter of the report by name, `silent`
/// and `quiet` as booleans, and `warning` while the line is silent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssRow(pub GnssLinkReport);

impl GnssRow {
    fn to_value(self) -> Value {
        let mut v = serde_json::to_value(self.0).unwrap_or(Value::Null);
        if let Value::Object(map) = &mut v {
            for field in LAYOUT_FIELDS {
                map.remove(field);
            }
            map.insert("silent".into(), Value::Bool(self.0.silent != 0));
            map.insert("quiet".into(), Value::Bool(self.0.quiet != 0));
            if self.0.silent != 0 {
                map.insert("warning".into(), Value::String(SILENT_WARNING.into()));
            }
        }
        v
    }
}

impl Serialize for GnssRow {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.to_value().serialize(s)
    }
}

/// The printable GNSS line of a report (the health report's `gnss`, or the last one a run saw);
/// `None` while the gnss service has not been heard (none
/// is fitted, or it has not reported yet).
pub fn gnss_row(gnss: &GnssLinkReport) -> Option<GnssRow> {
    (gnss.heard != 0).then_some(GnssRow(*gnss))
}

/// The table's `gnss` lines; nothing without a report.
pub fn gnss_lines(gnss: Option<&GnssRow>) -> String {
    let Some(GnssRow(g)) = gnss else {
        return String::new();
    };
    let unused = g.unused_gsv
        + g.unused_gsa
        + g.unused_zda
        + g.unused_txt
        + g.unused_gbs
        + g.unused_other_nmea
        + g.unused_proprietary
        + g.unused_other_messages;
    let mut out = format!(
        "gnss         {} bytes, {} epochs published ({} without fix), {} sentences and {} UBX \
         frames used, {unused} unused, checksum {} (without {}), malformed {}, resyncs {}, \
         {} bytes unframed, line ends {} CR LF / {} LF, reconnects {}{}\n",
        g.bytes,
        g.published,
        g.epochs_without_fix,
        g.sentences_used,
        g.ubx_frames_used,
        g.checksum_errors,
        g.without_checksum,
        g.malformed,
        g.resyncs,
        g.unframed_bytes,
        g.lines_crlf,
        g.lines_lf,
        g.reconnects,
        if g.quiet != 0 { ", quiet" } else { "" },
    );
    if g.silent != 0 {
        out.push_str(&format!("gnss         WARNING: {SILENT_WARNING}\n"));
    }
    out
}

/// The run summary's GNSS line: what the line carried and how much of it was used, and a warning
/// when it was silent at some time of the run.
pub fn summary_line(g: &GnssRow) -> String {
    let g = &g.0;
    let mut out = format!(
        "  gnss line: {} epochs published ({} without fix), {} bytes, {} sentences and {} UBX \
         frames used, {} checksum failures, {} malformed\n",
        g.published,
        g.epochs_without_fix,
        g.bytes,
        g.sentences_used,
        g.ubx_frames_used,
        g.checksum_errors,
        g.malformed
    );
    if g.silent_episodes > 0 {
        out.push_str(&format!(
            "  WARNING: gnss line silent {} time(s): {SILENT_WARNING}\n",
            g.silent_episodes
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_row_names_every_counter_and_warns_while_silent() {
        assert_eq!(gnss_row(&GnssLinkReport::default()), None);
        assert_eq!(gnss_lines(None), "");
        let report = GnssLinkReport {
            heard: 1,
            silent: 1,
            bytes: 20_000,
            checksum_errors: 300,
            without_checksum: 300,
            lines_lf: 300,
            ..GnssLinkReport::default()
        };
        let row = gnss_row(&report).expect("heard");
        let json = serde_json::to_value(row).expect("serialisable");
        assert_eq!(json["bytes"], 20_000);
        assert_eq!(json["without_checksum"], 300);
        assert_eq!(json["silent"], true);
        assert_eq!(json["quiet"], false);
        assert_eq!(json["warning"], SILENT_WARNING);
        for field in LAYOUT_FIELDS {
            assert!(json.get(field).is_none(), "{field} in {json}");
        }
        let text = gnss_lines(Some(&row));
        assert!(
            text.contains("20000 bytes, 0 epochs published")
                && text.contains("checksum 300 (without 300)")
                && text.contains("line ends 0 CR LF / 300 LF")
                && text.contains("WARNING: the line carries bytes but no usable"),
            "{text}"
        );
        let flowing = GnssRow(GnssLinkReport {
            silent: 0,
            published: 5,
            ..report
        });
        assert!(
            serde_json::to_value(flowing)
                .expect("json")
                .get("warning")
                .is_none()
        );
        assert!(!gnss_lines(Some(&flowing)).contains("WARNING"));
        assert!(summary_line(&flowing).starts_with("  gnss line: 5 epochs published"));
        assert!(!summary_line(&flowing).contains("WARNING"));
        let once_silent = GnssRow(GnssLinkReport {
            silent_episodes: 2,
            ..flowing.0
        });
        assert!(summary_line(&once_silent).contains("WARNING: gnss line silent 2 time(s)"));
    }
}
