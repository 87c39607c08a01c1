//! Decides when the serial line deserves a word to the operator: bytes that never make a valid
//! frame for a whole window (wrong baud rate, wrong protocol), or no bytes at all. Each is said
//! once, and said again only after valid frames have flowed in between. Pure: the loop feeds it
//! the decoder's counters and logs what it returns.

use ipc_types::LinkError;
use rins_protocol::{DecoderStats, likely_cause, link_error};

/// How long the line may carry bytes without a valid frame, or nothing at all, before it is
/// reported, ns.
pub const WINDOW_NS: u64 = 1_000_000_000;

/// Something wrong with the line, once per episode.
#[derive(Debug, Clone, PartialEq)]
pub enum LineWarning {
    /// No byte arrived for `silent_ns`.
    NoBytes {
        /// Time without a byte, ns.
        silent_ns: u64,
    },
    /// Bytes arrived for a window, none of them a valid frame.
    NoValidFrame {
        /// Bytes read since the last valid frame (or since the device was opened).
        bytes: u64,
        /// Their rate over the window, bytes per second.
        bytes_per_s: f64,
        /// Bytes discarded over the same time.
        discarded: u64,
        /// Why the last undecodable bytes were refused.
        last_error: LinkError,
    },
}

impl LineWarning {
    /// The warning as the operator reads it, naming the device `port`.
    pub fn message(&self, port: &str) -> String {
        match self {
            LineWarning::NoBytes { silent_ns } => format!(
                "no bytes from {port} in {:.0} s: is the device powered, connected and sending?",
                *silent_ns as f64 * 1e-9
            ),
            LineWarning::NoValidFrame {
                bytes,
                bytes_per_s,
                discarded,
                last_error,
            } => format!(
                "no valid frame from {port}: {bytes} bytes at {bytes_per_s:.0} B/s, {discarded} \
                 discarded, last decode error {}: {}",
                last_error.name(),
                likely_cause(*last_error, *discarded)
            ),
        }
    }
}

/// Where the counters stood when the current window without valid frames began.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Mark {
    at_ns: u64,
    bytes: u64,
    discarded: u64,
}

/// The line's watcher: one per acquisition process.
#[derive(Debug, Clone, PartialEq)]
pub struct LineWatch {
    /// Valid frames counted so far.
    valid: u64,
    /// Bytes counted so far, and when they last grew.
    bytes: u64,
    last_byte_ns: u64,
    /// The counters before the first byte since the last valid frame (or since opening).
    garbage_since: Option<Mark>,
    /// The previous observation's counters: where a window that begins now starts.
    prev_bytes: u64,
    prev_discarded: u64,
    warned_no_bytes: bool,
    warned_no_frame: bool,
}

impl LineWatch {
    /// A watcher for a device opened at `now_ns` whose decoder stands at `stats`.
    pub fn new(now_ns: u64, stats: &DecoderStats) -> Self {
        Self {
            valid: stats.valid_frames(),
            bytes: stats.bytes,
            last_byte_ns: now_ns,
            garbage_since: None,
            prev_bytes: stats.bytes,
            prev_discarded: stats.resync_bytes,
            warned_no_bytes: false,
            warned_no_frame: false,
        }
    }

    /// The device was (re)opened at `now_ns`: the time before does not count as silence or
    /// garbage of this device. What was said stays said until valid frames flow.
    pub fn opened(&mut self, now_ns: u64, stats: &DecoderStats) {
        let (no_bytes, no_frame) = (self.warned_no_bytes, self.warned_no_frame);
        *self = Self {
            warned_no_bytes: no_bytes,
            warned_no_frame: no_frame,
            ..Self::new(now_ns, stats)
        };
    }

    /// Looks at the decoder's counters at `now_ns` (called after every read, at least every read
    /// timeout); a warning when one is due.
    pub fn observe(&mut self, now_ns: u64, stats: &DecoderStats) -> Option<LineWarning> {
        let (prev_bytes, prev_discarded) = (self.prev_bytes, self.prev_discarded);
        self.prev_bytes = stats.bytes;
        self.prev_discarded = stats.resync_bytes;
        if stats.valid_frames() > self.valid {
            // Frames flow: everything is re-armed.
            *self = Self::new(now_ns, stats);
            return None;
        }
        if stats.bytes > self.bytes {
            self.bytes = stats.bytes;
            self.last_byte_ns = now_ns;
            self.garbage_since.get_or_insert(Mark {
                at_ns: now_ns,
                bytes: prev_bytes,
                discarded: prev_discarded,
            });
        }
        let silent_ns = now_ns.saturating_sub(self.last_byte_ns);
        if !self.warned_no_bytes && silent_ns >= WINDOW_NS {
            self.warned_no_bytes = true;
            return Some(LineWarning::NoBytes { silent_ns });
        }
        let mark = self.garbage_since?;
        let elapsed_ns = now_ns.saturating_sub(mark.at_ns);
        if self.warned_no_frame || elapsed_ns < WINDOW_NS {
            return None;
        }
        self.warned_no_frame = true;
        let bytes = stats.bytes - mark.bytes;
        Some(LineWarning::NoValidFrame {
            bytes,
            bytes_per_s: bytes as f64 / (elapsed_ns as f64 * 1e-9),
            discarded: stats.resync_bytes.saturating_sub(mark.discarded),
            last_error: link_error(stats.last_error.as_ref()),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_protocol::DecodeError;

    const MS: u64 = 1_000_000;

    fn garbage(bytes: u64) -> DecoderStats {
        DecoderStats {
            bytes,
            resync_bytes: bytes,
            last_error: Some(DecodeError::NoSync),
            ..DecoderStats::default()
        }
    }

    #[test]
    fn garbage_for_a_second_is_reported_once_with_rate_and_cause() {
        let mut w = LineWatch::new(0, &DecoderStats::default());
        // 9600 B/s in 50 ms reads.
        let mut warnings = Vec::new();
        for k in 1..=60u64 {
            if let Some(warning) = w.observe(k * 50 * MS, &garbage(k * 480)) {
                warnings.push((k, warning));
            }
        }
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        let (k, warning) = &warnings[0];
        // The window starts at the first bytes (50 ms), so it closes at 1050 ms.
        assert_eq!(*k, 21);
        let LineWarning::NoValidFrame {
            bytes,
            bytes_per_s,
            discarded,
            last_error,
        } = warning
        else {
            panic!("{warning:?}")
        };
        assert_eq!(
            (*bytes, *discarded, *last_error),
            (21 * 480, 21 * 480, LinkError::NoSync)
        );
        assert!((bytes_per_s - 10_080.0).abs() < 1.0, "{bytes_per_s}");
        let text = warning.message("/dev/ttyUSB0");
        assert!(
            text.starts_with("no valid frame from /dev/ttyUSB0: 10080 bytes at 10080 B/s")
                && text.contains("last decode error no-sync: no sync word in 10080 bytes"),
            "{text}"
        );
    }

    #[test]
    fn silence_is_reported_once_and_frames_rearm_both() {
        let mut w = LineWatch::new(0, &DecoderStats::default());
        assert_eq!(w.observe(999 * MS, &DecoderStats::default()), None);
        let warning = w.observe(1000 * MS, &DecoderStats::default());
        assert_eq!(
            warning,
            Some(LineWarning::NoBytes {
                silent_ns: 1000 * MS
            })
        );
        assert!(
            warning
                .unwrap()
                .message("/dev/null")
                .starts_with("no bytes from /dev/null in 1 s")
        );
        assert_eq!(w.observe(5000 * MS, &DecoderStats::default()), None);
        // Frames flow again, then stop: said again.
        let flowing = DecoderStats {
            frames: 10,
            bytes: 600,
            ..DecoderStats::default()
        };
        assert_eq!(w.observe(5100 * MS, &flowing), None);
        assert!(matches!(
            w.observe(6100 * MS, &flowing),
            Some(LineWarning::NoBytes { .. })
        ));
    }

    #[test]
    fn frames_flowing_mean_no_warning_and_a_reopen_restarts_the_clock() {
        let mut w = LineWatch::new(0, &DecoderStats::default());
        for k in 1..=100u64 {
            let s = DecoderStats {
                frames: k * 50,
                bytes: k * 3000,
                resync_bytes: 7,
                ..DecoderStats::default()
            };
            assert_eq!(w.observe(k * 50 * MS, &s), None, "{k}");
        }
        // The device is away 10 s; once reopened, silence counts from the reopening.
        let s = w.prev_stats();
        w.opened(15_000 * MS, &s);
        assert_eq!(w.observe(15_500 * MS, &s), None);
        assert!(w.observe(16_000 * MS, &s).is_some());
    }

    impl LineWatch {
        fn prev_stats(&self) -> DecoderStats {
            DecoderStats {
                frames: self.valid,
                bytes: self.prev_bytes,
                resync_bytes: self.prev_discarded,
                ..DecoderStats::default()
            }
        }
    }
}
