//! The `link` part of `rins status`: the serial line as acquisition last reported it, with the
//! last decode error by name.

use ipc_types::LinkReport;
use rins_watchdog::link::link_error_name;
use serde::Serialize;

/// The serial line as printed (`link` in the JSON); absent until acquisition has been heard.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct LinkRow {
    /// Bytes read from the device.
    pub bytes_received: u64,
    /// Frames with a valid CRC and sane content.
    pub valid_frames: u64,
    /// Bytes skipped because they belonged to no valid frame.
    pub discarded_bytes: u64,
    /// Frames with a bad CRC.
    pub crc_errors: u64,
    /// Frames with a valid CRC and malformed content.
    pub malformed: u64,
    /// Times the device was reopened.
    pub reconnects: u64,
    /// Why the last undecodable bytes were refused: `none`, `no-sync`, `crc-mismatch`, ...
    pub last_decode_error: String,
}

/// The printable link of a report; `None` while acquisition has not been heard.
pub fn link_row(link: &LinkReport) -> Option<LinkRow> {
    (link.heard != 0).then(|| LinkRow {
        bytes_received: link.bytes_received,
        valid_frames: link.valid_frames,
        discarded_bytes: link.discarded_bytes,
        crc_errors: link.crc_errors,
        malformed: link.malformed,
        reconnects: link.reconnects,
        last_decode_error: link_error_name(link.last_decode_error),
    })
}

/// The table's `link` line.
pub fn link_line(link: Option<&LinkRow>) -> String {
    match link {
        None => "link         not heard from acquisition yet\n".to_string(),
        Some(l) => format!(
            "link         {} bytes, {} valid frames, {} discarded, crc {}, malformed {}, \
             reconnects {}, last decode error {}\n",
            l.bytes_received,
            l.valid_frames,
            l.discarded_bytes,
            l.crc_errors,
            l.malformed,
            l.reconnects,
            l.last_decode_error
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
        assert_eq!(row.last_decode_error, "no-sync");
        let json = serde_json::to_value(&row).expect("serialisable");
        assert_eq!(json["last_decode_error"], "no-sync");
        assert_eq!(json["bytes_received"], 9600);
        let line = link_line(Some(&row));
        assert!(
            line.contains("9600 bytes, 0 valid frames, 9600 discarded")
                && line.contains("reconnects 2, last decode error no-sync"),
            "{line}"
        );
    }
}
