//! What a listen on a serial line found, from the decoder's counters: bytes, frame rates per type,
//! refusals, and a one-line verdict; and, over listens at several baud rates, which rate carries
//! the device's frames. Pure: the listening itself is the caller's.

use ipc_types::LinkError;

use super::decoder::DecoderStats;
use super::diagnosis::{likely_cause, link_error};
use super::frame::DecodedFrame;
use super::frame_type::FrameType;

/// Frames of one type seen during a listen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TypeRate {
    /// The frame type.
    pub frame_type: FrameType,
    /// Frames of this type handed out.
    pub frames: u64,
    /// The device's rate: frames per second of device time between the first and the last frame
    /// of the type (the arrival rate when fewer than two frames came). A device catching up on a
    /// backlog, or a driver handing over bytes in bursts, does not change it; frames lost on the
    /// line lower it.
    pub hz: f64,
    /// Frames per second of the listen: what arrived.
    pub arrival_hz: f64,
}

/// Device time of the first and the last frame of each type handed out, for the device's rates.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DeviceSpans {
    first_us: [Option<u64>; FrameType::COUNT],
    last_us: [Option<u64>; FrameType::COUNT],
}

impl DeviceSpans {
    /// Takes a frame the decoder handed out.
    pub fn observe(&mut self, frame: &DecodedFrame) {
        let i = frame.payload.frame_type().index();
        self.first_us[i].get_or_insert(frame.device_time_us);
        self.last_us[i] = Some(frame.device_time_us);
    }

    /// Device seconds from the first to the last frame of `t`; `None` before two distinct times.
    pub fn span_s(&self, t: FrameType) -> Option<f64> {
        let (first, last) = (self.first_us[t.index()]?, self.last_us[t.index()]?);
        (last > first).then(|| (last - first) as f64 * 1e-6)
    }
}

/// What the line carried during one listen.
#[derive(Debug, Clone, PartialEq)]
pub struct LineReport {
    /// Length of the listen, s.
    pub seconds: f64,
    /// Bytes read.
    pub bytes: u64,
    /// Frames with a valid CRC and sane content.
    pub valid_frames: u64,
    /// Every frame type seen, in [`FrameType::ALL`] order.
    pub types: Vec<TypeRate>,
    /// Candidate frames with a bad CRC.
    pub crc_errors: u64,
    /// Candidate frames with a valid CRC and malformed content.
    pub malformed: u64,
    /// Bytes discarded while searching for frames.
    pub discarded_bytes: u64,
    /// Why the last undecodable bytes were refused.
    pub last_error: LinkError,
}

/// The gist of a [`LineReport`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineVerdict {
    /// Valid frames arrived.
    Frames,
    /// Bytes arrived, none of them a valid frame.
    BytesWithoutFrames,
    /// Nothing arrived.
    NoBytes,
}

impl LineReport {
    /// The report of a listen of `seconds` (> 0) whose decoder ended with `stats` (a fresh decoder
    /// per listen: the counters are taken as the listen's own) and whose frames spanned `spans`.
    pub fn from_listen(stats: &DecoderStats, spans: &DeviceSpans, seconds: f64) -> Self {
        let types = FrameType::ALL
            .into_iter()
            .filter_map(|t| {
                let frames = stats.frames_by_type[t.index()];
                let arrival_hz = frames as f64 / seconds;
                (frames > 0).then(|| TypeRate {
                    frame_type: t,
                    frames,
                    hz: spans
                        .span_s(t)
                        .map_or(arrival_hz, |span| (frames - 1) as f64 / span),
                    arrival_hz,
                })
            })
            .collect();
        Self {
            seconds,
            bytes: stats.bytes,
            valid_frames: stats.valid_frames(),
            types,
            crc_errors: stats.crc_errors,
            malformed: stats.malformed,
            discarded_bytes: stats.resync_bytes,
            last_error: link_error(stats.last_error.as_ref()),
        }
    }

    /// Frames, bytes without frames, or nothing.
    pub fn verdict(&self) -> LineVerdict {
        if self.valid_frames > 0 {
            LineVerdict::Frames
        } else if self.bytes > 0 {
            LineVerdict::BytesWithoutFrames
        } else {
            LineVerdict::NoBytes
        }
    }

    /// The verdict as one line, e.g. `rins frames at 1000 Hz imu, 50 Hz baro, 100 Hz mag`.
    pub fn verdict_line(&self) -> String {
        match self.verdict() {
            LineVerdict::Frames => {
                let rates: Vec<String> = self
                    .types
                    .iter()
                    .map(|t| format!("{:.0} Hz {}", t.hz, t.frame_type.name()))
                    .collect();
                let mut line = format!("rins frames at {}", rates.join(", "));
                if self.crc_errors + self.malformed > 0 {
                    line.push_str(&format!(
                        ", with {} CRC failures and {} malformed frames ({})",
                        self.crc_errors,
                        self.malformed,
                        likely_cause(self.last_error, self.discarded_bytes)
                    ));
                }
                line
            }
            LineVerdict::BytesWithoutFrames => format!(
                "bytes but no valid frame: wrong baud rate or protocol ({})",
                likely_cause(self.last_error, self.discarded_bytes)
            ),
            LineVerdict::NoBytes => format!(
                "no bytes in {:.1} s: is the device powered, connected and sending?",
                self.seconds
            ),
        }
    }
}

/// What a scan over baud rates concluded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ScanOutcome {
    /// The rate with the most valid frames (fewest refusals on a tie); `None` when no rate gave one.
    pub best_baud: Option<u32>,
    /// One line for the operator.
    pub verdict: String,
}

/// Which of the listens `(baud, report)` carries the device's frames. When every rate of two or
/// more gave frames, the port does not apply the rate (a pseudo-terminal, a USB device that
/// ignores it), and the scan cannot tell the device's rate: the verdict says so.
pub fn scan_outcome(results: &[(u32, LineReport)]) -> ScanOutcome {
    let with_frames: Vec<&(u32, LineReport)> =
        results.iter().filter(|(_, r)| r.valid_frames > 0).collect();
    let best = with_frames
        .iter()
        .max_by_key(|(baud, r)| {
            (
                r.valid_frames,
                std::cmp::Reverse(r.crc_errors + r.malformed),
                std::cmp::Reverse(*baud),
            )
        })
        .map(|(baud, _)| *baud);
    let verdict = match best {
        None if results.iter().all(|(_, r)| r.bytes == 0) => {
            "no bytes at any baud rate: is the device powered, connected and sending?".to_string()
        }
        None => "no baud rate gave a valid frame: not a rins device, or a rate not tried".into(),
        Some(baud) if results.len() >= 2 && with_frames.len() == results.len() => format!(
            "valid frames at every baud rate tried: the port does not apply the rate (a \
             pseudo-terminal?), so the scan cannot tell the device's; most frames at {baud}"
        ),
        Some(baud) => {
            let others: Vec<String> = with_frames
                .iter()
                .filter(|(b, _)| *b != baud)
                .map(|(b, _)| b.to_string())
                .collect();
            if others.is_empty() {
                format!("rins frames at {baud} baud only")
            } else {
                format!(
                    "rins frames best at {baud} baud (also some at {})",
                    others.join(", ")
                )
            }
        }
    };
    ScanOutcome {
        best_baud: best,
        verdict,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DecodeError, Decoder};

    /// Counters with `by_type` frames of the first types (the others none).
    fn stats(by_type: [u64; 4], bytes: u64, resync: u64) -> DecoderStats {
        let mut frames_by_type = [0; FrameType::COUNT];
        frames_by_type[..by_type.len()].copy_from_slice(&by_type);
        DecoderStats {
            frames: by_type.iter().sum(),
            frames_by_type,
            bytes,
            resync_bytes: resync,
            ..DecoderStats::default()
        }
    }

    fn from_stats(stats: &DecoderStats, seconds: f64) -> LineReport {
        LineReport::from_listen(stats, &DeviceSpans::default(), seconds)
    }

    #[test]
    fn device_time_gives_the_device_rate_whatever_the_arrival() {
        use crate::{BaroFrame, Payload};
        let mut spans = DeviceSpans::default();
        // 1500 baro frames 20 ms apart (50 Hz on the device), arrived within 3 s: a backlog.
        for k in 0..1500u64 {
            spans.observe(&DecodedFrame {
                seq: k,
                device_time_us: 1_000_000 + k * 20_000,
                payload: Payload::Baro(BaroFrame::default()),
            });
        }
        let r = LineReport::from_listen(&stats([0, 1500, 0, 0], 60_000, 0), &spans, 3.0);
        assert_eq!(r.types.len(), 1);
        assert!((r.types[0].hz - 50.0).abs() < 1e-9, "{:?}", r.types[0]);
        assert_eq!(r.types[0].arrival_hz, 500.0);
    }

    #[test]
    fn frames_give_rates_per_type_and_the_verdict_names_them() {
        let r = from_stats(&stats([3000, 150, 300, 0], 120_000, 0), 3.0);
        assert_eq!(r.verdict(), LineVerdict::Frames);
        assert_eq!(r.types.len(), 3);
        assert_eq!(
            (r.types[0].frame_type, r.types[0].hz),
            (FrameType::Imu, 1000.0)
        );
        assert_eq!(r.types[1].hz, 50.0);
        assert_eq!(
            r.verdict_line(),
            "rins frames at 1000 Hz imu, 50 Hz baro, 100 Hz mag"
        );
    }

    #[test]
    fn garbage_and_silence_have_their_own_verdicts() {
        let mut d = Decoder::new();
        // No 0xA5 at all: not even the start of a sync word.
        let garbage: Vec<u8> = (0..9600u32).map(|i| (i * 7 % 160) as u8).collect();
        d.push(&garbage, 0, |_| panic!("no frame in garbage"));
        let r = from_stats(&d.stats(), 1.0);
        assert_eq!(r.verdict(), LineVerdict::BytesWithoutFrames);
        assert_eq!((r.bytes, r.discarded_bytes), (9600, 9600));
        assert_eq!(r.last_error, LinkError::NoSync);
        assert_eq!(
            r.verdict_line(),
            "bytes but no valid frame: wrong baud rate or protocol (no sync word in 9600 bytes: \
             wrong baud rate or not a rins device?)"
        );
        let silent = from_stats(&DecoderStats::default(), 3.0);
        assert_eq!(silent.verdict(), LineVerdict::NoBytes);
        assert!(silent.verdict_line().starts_with("no bytes in 3.0 s"));
        let crc = DecoderStats {
            crc_errors: 4,
            last_error: Some(DecodeError::CrcMismatch {
                received: 0,
                computed: 1,
            }),
            ..stats([100, 0, 0, 0], 5000, 200)
        };
        let line = from_stats(&crc, 1.0).verdict_line();
        assert!(
            line.contains("with 4 CRC failures") && line.contains("line noise"),
            "{line}"
        );
    }

    fn report(valid: u64, bytes: u64, crc: u64) -> LineReport {
        LineReport {
            crc_errors: crc,
            ..from_stats(&stats([valid, 0, 0, 0], bytes, 0), 1.0)
        }
    }

    #[test]
    fn scan_picks_the_rate_with_frames() {
        let results = [
            (9600, report(0, 960, 0)),
            (115_200, report(0, 11_520, 3)),
            (921_600, report(1000, 44_000, 0)),
        ];
        let o = scan_outcome(&results);
        assert_eq!(o.best_baud, Some(921_600));
        assert_eq!(o.verdict, "rins frames at 921600 baud only");
        // A neighbouring rate that lets a few frames through: the one with most frames wins.
        let results = [
            (460_800, report(12, 40_000, 900)),
            (921_600, report(1000, 44_000, 0)),
            (9600, report(0, 960, 0)),
        ];
        let o = scan_outcome(&results);
        assert_eq!(o.best_baud, Some(921_600));
        assert!(o.verdict.contains("also some at 460800"), "{}", o.verdict);
    }

    #[test]
    fn scan_says_when_the_rate_makes_no_difference_or_nothing_fits() {
        // A pseudo-terminal: every rate carries the same frames.
        let pty = [
            (9600, report(1000, 44_000, 0)),
            (921_600, report(999, 44_000, 0)),
        ];
        let o = scan_outcome(&pty);
        assert_eq!(o.best_baud, Some(9600));
        assert!(
            o.verdict.contains("does not apply the rate"),
            "{}",
            o.verdict
        );
        let garbage = [(9600, report(0, 960, 0)), (921_600, report(0, 90_000, 5))];
        let o = scan_outcome(&garbage);
        assert_eq!(o.best_baud, None);
        assert!(o.verdict.starts_with("no baud rate gave"), "{}", o.verdict);
        let silent = [(9600, report(0, 0, 0)), (921_600, report(0, 0, 0))];
        assert!(scan_outcome(&silent).verdict.starts_with("no bytes at any"));
    }
}
