//! The serial line as the watchdog sees it through acquisition's heartbeats: the health report's
//! `link`, the status line's note when bytes arrive without frames or nothing arrives, and the
//! verdict of a timed run in which no valid frame arrived.

use ipc_types::{LinkError, LinkReport};
use rins_protocol::likely_cause;

use crate::device_counters::DeviceCounters;
use crate::summary::Summary;

/// The health report's `link` from acquisition's counters (summed over its restarts); `heard`:
/// a heartbeat of acquisition has arrived.
pub fn report_of(c: &DeviceCounters, heard: bool) -> LinkReport {
    LinkReport {
        heard: u8::from(heard),
        last_decode_error: c.last_decode_error,
        bytes_received: c.bytes_received,
        valid_frames: c.valid_frames,
        discarded_bytes: c.resync_bytes,
        crc_errors: c.crc_errors,
        malformed: c.malformed_frames,
        reconnects: c.reconnects,
        ..LinkReport::default()
    }
}

/// The name of a [`LinkError`] byte; a number this build does not know is named by its value.
pub fn link_error_name(code: u8) -> String {
    LinkError::from_u8(code).map_or_else(|| format!("error {code}"), |e| e.name().to_string())
}

/// One acquisition heartbeat, as far as the line is concerned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Beat {
    pid: u32,
    at_ns: u64,
    counters: DeviceCounters,
}

/// Acquisition's last two heartbeats: what the line did in the second between them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkRate {
    prev: Option<Beat>,
    last: Option<Beat>,
}

impl LinkRate {
    /// A heartbeat of acquisition process `pid`, sent at `at_ns`, with its `counters`.
    pub fn observe(&mut self, pid: u32, at_ns: u64, counters: &DeviceCounters) {
        self.prev = self.last;
        self.last = Some(Beat {
            pid,
            at_ns,
            counters: *counters,
        });
    }

    /// The status line's note on the line, only when something is wrong between the last two
    /// heartbeats of one acquisition process: `no valid frame: 9600 B/s discarded (no-sync)` when
    /// bytes arrived without a valid frame, `no bytes from the device` when nothing arrived.
    pub fn status_note(&self) -> Option<String> {
        let (Some(prev), Some(last)) = (self.prev, self.last) else {
            return None;
        };
        // A restarted acquisition counts from zero: the difference would mean nothing.
        if prev.pid != last.pid || last.at_ns <= prev.at_ns {
            return None;
        }
        let (a, b) = (&prev.counters, &last.counters);
        if b.valid_frames > a.valid_frames {
            return None;
        }
        if b.bytes_received == a.bytes_received {
            return Some("no bytes from the device".into());
        }
        let dt_s = (last.at_ns - prev.at_ns) as f64 * 1e-9;
        let discarded = b.resync_bytes.saturating_sub(a.resync_bytes);
        Some(format!(
            "no valid frame: {:.0} B/s discarded ({})",
            discarded as f64 / dt_s,
            link_error_name(b.last_decode_error)
        ))
    }
}

/// Why a timed run that read `port` failed, when no valid frame arrived in all of it: what the
/// line carried and its likely cause. `None` when frames arrived.
pub fn no_valid_frame(port: &str, s: &Summary) -> Option<String> {
    if s.valid_frames > 0 {
        return None;
    }
    let seen = if s.bytes_received == 0 {
        format!(
            "0 bytes received: is it the device's path, and is the device powered, connected and \
             sending? (`rins probe --port {port}` listens to it; acquisition's log says why it \
             could not open it)"
        )
    } else {
        let last = LinkError::from_name(&s.last_decode_error).unwrap_or(LinkError::None);
        format!(
            "{} bytes received, {} discarded, {} CRC failures, {} malformed, last decode error \
             {}: {}",
            s.bytes_received,
            s.discarded_bytes,
            s.crc_errors,
            s.malformed_frames,
            s.last_decode_error,
            likely_cause(last, s.discarded_bytes)
        )
    };
    Some(format!(
        "no valid frame from {port} in {:.1} s: {seen}",
        s.duration_s
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: u64 = 1_000_000_000;

    fn counters(bytes: u64, valid: u64, discarded: u64) -> DeviceCounters {
        DeviceCounters {
            bytes_received: bytes,
            valid_frames: valid,
            resync_bytes: discarded,
            last_decode_error: LinkError::NoSync as u8,
            ..DeviceCounters::default()
        }
    }

    #[test]
    fn the_note_appears_only_without_valid_frames() {
        let mut rate = LinkRate::default();
        rate.observe(7, S, &counters(0, 0, 0));
        assert_eq!(rate.status_note(), None, "one heartbeat is no rate");
        rate.observe(7, 2 * S, &counters(9600, 0, 9600));
        assert_eq!(
            rate.status_note().as_deref(),
            Some("no valid frame: 9600 B/s discarded (no-sync)")
        );
        rate.observe(7, 3 * S, &counters(9600, 0, 9600));
        assert_eq!(
            rate.status_note().as_deref(),
            Some("no bytes from the device")
        );
        rate.observe(7, 4 * S, &counters(60_000, 1000, 9600));
        assert_eq!(rate.status_note(), None, "frames flow");
        // A new acquisition process starts from zero: no note from the difference.
        rate.observe(8, 5 * S, &counters(0, 0, 0));
        assert_eq!(rate.status_note(), None);
    }

    #[test]
    fn the_report_carries_the_counters_and_names_the_error() {
        let c = DeviceCounters {
            crc_errors: 3,
            malformed_frames: 2,
            reconnects: 1,
            ..counters(500, 10, 40)
        };
        let r = report_of(&c, true);
        assert_eq!(
            (r.heard, r.bytes_received, r.valid_frames, r.discarded_bytes),
            (1, 500, 10, 40)
        );
        assert_eq!((r.crc_errors, r.malformed, r.reconnects), (3, 2, 1));
        assert_eq!(link_error_name(r.last_decode_error), "no-sync");
        assert_eq!(link_error_name(200), "error 200");
    }

    #[test]
    fn a_run_without_frames_names_the_port_and_what_it_saw() {
        let ok = Summary {
            valid_frames: 1,
            ..Summary::default()
        };
        assert_eq!(no_valid_frame("/dev/ttyUSB0", &ok), None);
        let silent = Summary {
            duration_s: 3.0,
            ..Summary::default()
        };
        let msg = no_valid_frame("/dev/null", &silent).unwrap_or_default();
        assert!(
            msg.starts_with("no valid frame from /dev/null in 3.0 s: 0 bytes received"),
            "{msg}"
        );
        let garbage = Summary {
            duration_s: 3.0,
            bytes_received: 28_800,
            discarded_bytes: 28_790,
            last_decode_error: "no-sync".into(),
            ..Summary::default()
        };
        let msg = no_valid_frame("/dev/pts/3", &garbage).unwrap_or_default();
        assert!(
            msg.contains("28800 bytes received, 28790 discarded")
                && msg.contains("last decode error no-sync: no sync word in 28790 bytes"),
            "{msg}"
        );
    }
}
