//! The `link` part of `rins status`: the serial line as acquisition last reported it, with the
//! last decode error by name.

use ipc_types::LinkReport;
use rins_watchdog::link::link_error_name;
use serde::ser::{Serialize, SerializeStruct, Serializer};

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

/// The table's `link` line.
pub fn link_line(link: Option<&LinkRow>) -> String {
    match link {
        None => "link         not heard from acquisition yet\n".to_string(),
        Some(LinkRow(l)) => format!(
            "link         {} bytes, {} valid frames, {} discarded, crc {}, malformed {}, \
             reconnects {}, last decode error {}\n",
            l.bytes_received,
            l.valid_frames,
            l.discarded_bytes,
            l.crc_errors,
            l.malformed,
            l.reconnects,
            link_error_name(l.last_decode_error)
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::LinkError;

    #[test]
    fn the_link_names_its_error_and_is_absent_until_heard() {
        assert_eq!(link_row(&LinkReport::default()), None);
        assert!(link_line(None).contains("not heard"));
        let report = LinkReport {
            heard: 1,
            last_decode_error: LinkError::NoSync as u8,
            bytes_received: 9600,
            discarded_bytes: 9600,
            reconnects: 2,
            ..LinkReport::default()
        };
        let row = link_row(&report).expect("heard");
        let json = serde_json::to_value(row).expect("serialisable");
        assert_eq!(json["last_decode_error"], "no-sync");
        assert_eq!(json["bytes_received"], 9600);
        assert_eq!(json["valid_frames"], 0);
        assert!(
            json.get("heard").is_none() && json.get("_pad").is_none(),
            "{json}"
        );
        let line = link_line(Some(&row));
        assert!(
            line.contains("9600 bytes, 0 valid frames, 9600 discarded")
                && line.contains("reconnects 2, last decode error no-sync"),
            "{line}"
        );
    }
}
