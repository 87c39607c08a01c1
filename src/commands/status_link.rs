//! The `link` part of `rins status`: the serial line as acquisition last reported it, with the
//! last decode error by name.

use rins_watchdog::link::link_error_name;
use rins_watchdog::status_rows::LinkRow;

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
    use ipc_types::{LinkError, LinkReport};
    use rins_watchdog::status_rows::link_row;

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
