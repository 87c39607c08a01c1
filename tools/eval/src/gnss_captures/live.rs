//! The captures played to a running `gnss` service through a pseudo-terminal: its published fixes
//! scored exactly as the in-process decoder's ([`super::score_capture`]), the bytes it read
//! checked against the bytes written, and its fixes compared one by one with the in-process
//! decoder's from the same bytes.

use std::fmt::Write as _;

use ipc_types::{GnssFix, GnssLinkReport};
use rins_gnss_protocol::decode::GnssDecoderStats;
use rins_gnss_protocol::decode::NmeaStats;
use rins_gnss_protocol::decode::framer::FramingStats;
use serde::Serialize;

use super::report::{CapturesReport, build, to_table};
use super::{CaptureResult, Failure, replay, score_capture};

/// What a running service made of one capture, as collected outside it.
#[derive(Debug, Clone, Default)]
pub struct LiveFeed {
    /// Receiver bytes written to the service's serial line.
    pub bytes_written: u64,
    /// Every fix it published, in order.
    pub fixes: Vec<GnssFix>,
    /// Its last line report (the final one, sent when it stopped), if any arrived.
    pub link: Option<GnssLinkReport>,
}

/// Fixes of one run that the other run has no identical fix for (same receiver time, latitude,
/// longitude, altitude and fix type, bit for bit), counted both ways.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct FixDifferences {
    /// Live fixes without an identical in-process fix.
    pub live_only: usize,
    /// In-process fixes without an identical live fix.
    pub in_process_only: usize,
}

impl FixDifferences {
    /// Both counts together.
    pub fn total(self) -> usize {
        self.live_only + self.in_process_only
    }
}

/// One capture's live run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveCapture {
    /// File name of the capture.
    pub name: String,
    /// Receiver bytes written to the line.
    pub bytes_written: u64,
    /// Bytes the service reported reading (its last line report; `None` without one).
    pub bytes_read_by_service: Option<u64>,
    /// Fixes received from the service.
    pub fixes_received: usize,
    /// Fixes of the in-process decoder from the same bytes.
    pub fixes_in_process: usize,
    /// The live fixes against the in-process ones.
    pub live_vs_in_process_differences: FixDifferences,
    /// The service's last line report, every counter of it.
    pub link: Option<GnssLinkReport>,
}

impl LiveCapture {
    /// Whether the service reported reading other than every byte written (unknown without a
    /// report: not a mismatch, listed apart).
    pub fn byte_mismatch(&self) -> bool {
        self.bytes_read_by_service
            .is_some_and(|read| read != self.bytes_written)
    }
}

/// Sums of the live runs.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct LiveTotals {
    /// Bytes written over every capture.
    pub bytes_written: u64,
    /// Bytes the services reported reading (captures with a report).
    pub bytes_read_by_service: u64,
    /// Captures whose service read other than the bytes written.
    pub byte_mismatches: Vec<String>,
    /// Captures whose service sent no line report.
    pub without_link_report: Vec<String>,
    /// Fixes received.
    pub fixes_received: usize,
    /// Differences to the in-process fixes, both ways.
    pub live_vs_in_process_differences: usize,
    /// Captures with such differences.
    pub differing_from_in_process: Vec<String>,
}

/// The live evaluation's report: the in-process report's figures from the live fixes, and the
/// line and comparison of each capture.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LiveCapturesReport {
    /// Always `"live"`.
    pub mode: &'static str,
    /// Line rate the bytes were written at, baud (10 bits per byte).
    pub baud: u32,
    /// Scores and sums, built as for the in-process run.
    #[serde(flatten)]
    pub report: CapturesReport,
    /// Each evaluated capture's live run, in the order of `captures`.
    pub live: Vec<LiveCapture>,
    /// Their sums.
    pub live_totals: LiveTotals,
}

/// Scores `feed`, the live run of capture `log` (gpsd's decode `chk`), and compares it with the
/// in-process decoder's run on the same bytes.
pub fn evaluate_live(
    name: &str,
    log: &[u8],
    chk: &str,
    feed: &LiveFeed,
) -> (CaptureResult, LiveCapture) {
    let (in_process, _) = replay::decode(replay::receiver_bytes(log));
    let counters = feed.link.as_ref().map(decoder_counters).unwrap_or_default();
    let result = score_capture(name, log, chk, &feed.fixes, counters);
    let live = LiveCapture {
        name: name.to_string(),
        bytes_written: feed.bytes_written,
        bytes_read_by_service: feed.link.map(|l| l.bytes),
        fixes_received: feed.fixes.len(),
        fixes_in_process: in_process.len(),
        live_vs_in_process_differences: fix_differences(&feed.fixes, &in_process),
        link: feed.link,
    };
    (result, live)
}

/// The decoder's counters as the service's line report carries them. The report counts
/// unreadable and out-of-range messages together: they are all `malformed` here.
pub fn decoder_counters(link: &GnssLinkReport) -> GnssDecoderStats {
    GnssDecoderStats {
        bytes: link.bytes,
        sentences: link.sentences_used,
        ubx_frames: link.ubx_frames_used,
        checksum_errors: link.checksum_errors,
        unparsable: 0,
        unsupported: link.unused_gsv
            + link.unused_gsa
            + link.unused_zda
            + link.unused_txt
            + link.unused_gbs
            + link.unused_other_nmea
            + link.unused_proprietary
            + link.unused_other_messages,
        malformed: link.malformed,
        epochs: link.epochs,
        epochs_without_fix: link.epochs_without_fix,
        ubx_late: link.ubx_late,
        nmea_epochs_superseded: link.nmea_epochs_superseded,
        framing: FramingStats {
            lines_crlf: link.lines_crlf,
            lines_lf: link.lines_lf,
            resyncs: link.resyncs,
            oversized: link.oversized,
            wrong_length: link.wrong_length,
            unframed_bytes: link.unframed_bytes,
        },
        nmea: NmeaStats {
            gsv: link.unused_gsv,
            gsa: link.unused_gsa,
            zda: link.unused_zda,
            txt: link.unused_txt,
            gbs: link.unused_gbs,
            other: link.unused_other_nmea,
            proprietary: link.unused_proprietary,
            nothing_to_use: link.nothing_to_use,
            without_checksum: link.without_checksum,
            ..NmeaStats::default()
        },
    }
}

/// What two fixes are compared on: receiver time, fix type, latitude, longitude, altitude (the
/// floats bit for bit, so that NaN altitudes compare equal).
type FixKey = (u64, u8, u64, u64, u64);

fn key(f: &GnssFix) -> FixKey {
    (
        f.receiver_time_us,
        f.fix_type,
        f.latitude_rad.to_bits(),
        f.longitude_rad.to_bits(),
        f.altitude_m.to_bits(),
    )
}

/// The fixes of `live` and `in_process` without an identical fix on the other side, each fix
/// paired at most once.
pub fn fix_differences(live: &[GnssFix], in_process: &[GnssFix]) -> FixDifferences {
    let mut a: Vec<FixKey> = live.iter().map(key).collect();
    let mut b: Vec<FixKey> = in_process.iter().map(key).collect();
    a.sort_unstable();
    b.sort_unstable();
    let (mut i, mut j, mut paired) = (0, 0, 0);
    while i < a.len() && j < b.len() {
        match a[i].cmp(&b[j]) {
            std::cmp::Ordering::Less => i += 1,
            std::cmp::Ordering::Greater => j += 1,
            std::cmp::Ordering::Equal => {
                paired += 1;
                i += 1;
                j += 1;
            }
        }
    }
    FixDifferences {
        live_only: a.len() - paired,
        in_process_only: b.len() - paired,
    }
}

/// The report of the live runs `runs` (in capture order) and the captures that could not be run.
pub fn build_live(
    runs: Vec<(CaptureResult, LiveCapture)>,
    failures: Vec<Failure>,
    baud: u32,
) -> LiveCapturesReport {
    let (captures, live): (Vec<_>, Vec<_>) = runs.into_iter().unzip();
    let mut t = LiveTotals::default();
    for c in &live {
        t.bytes_written += c.bytes_written;
        t.bytes_read_by_service += c.bytes_read_by_service.unwrap_or(0);
        t.fixes_received += c.fixes_received;
        let differences = c.live_vs_in_process_differences.total();
        t.live_vs_in_process_differences += differences;
        if c.byte_mismatch() {
            t.byte_mismatches.push(c.name.clone());
        }
        if c.link.is_none() {
            t.without_link_report.push(c.name.clone());
        }
        if differences > 0 {
            t.differing_from_in_process.push(c.name.clone());
        }
    }
    LiveCapturesReport {
        mode: "live",
        baud,
        report: build(captures, failures),
        live,
        live_totals: t,
    }
}

/// The live report as text: the in-process report's table of the live figures, then each
/// capture's line and comparison and their sums.
pub fn to_live_table(r: &LiveCapturesReport) -> String {
    let mut s = to_table(&r.report);
    let _ = writeln!(
        s,
        "\nlive: each capture written at {} baud to a running `rins service gnss`",
        r.baud
    );
    let _ = writeln!(
        s,
        "{:<34} {:>8} {:>8} {:>6} {:>6} {:>9} {:>9}",
        "capture", "written", "read", "fixes", "in-pr", "live-only", "inpr-only"
    );
    for c in &r.live {
        let read = c
            .bytes_read_by_service
            .map_or_else(|| "-".to_string(), |b| b.to_string());
        let d = c.live_vs_in_process_differences;
        let _ = writeln!(
            s,
            "{:<34} {:>8} {:>8} {:>6} {:>6} {:>9} {:>9}{}",
            c.name,
            c.bytes_written,
            read,
            c.fixes_received,
            c.fixes_in_process,
            d.live_only,
            d.in_process_only,
            if c.byte_mismatch() {
                "  BYTES LOST"
            } else {
                ""
            }
        );
    }
    let t = &r.live_totals;
    let _ = writeln!(
        s,
        "live total: {} bytes written, {} read by the services, {} fixes, {} differences to \
         in-process",
        t.bytes_written,
        t.bytes_read_by_service,
        t.fixes_received,
        t.live_vs_in_process_differences
    );
    for (what, names) in [
        ("bytes read != written", &t.byte_mismatches),
        ("no line report received", &t.without_link_report),
        ("fixes differ from in-process", &t.differing_from_in_process),
    ] {
        if !names.is_empty() {
            let _ = writeln!(s, "{what}: {}", names.join(", "));
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::GnssFixType;

    fn fix(t: u64, lat: f64) -> GnssFix {
        GnssFix {
            fix_type: GnssFixType::Fix3d as u8,
            receiver_time_us: t,
            latitude_rad: lat,
            altitude_m: f64::NAN,
            ..GnssFix::default()
        }
    }

    #[test]
    fn identical_fixes_pair_once_and_the_rest_is_counted_both_ways() {
        let live = [fix(1, 0.1), fix(2, 0.2), fix(2, 0.2), fix(3, 0.3)];
        let in_process = [
            fix(2, 0.2),
            fix(1, 0.1),
            fix(3, 0.30000000000000004),
            fix(4, 0.4),
        ];
        let d = fix_differences(&live, &in_process);
        assert_eq!(
            d,
            FixDifferences {
                live_only: 2,
                in_process_only: 2
            }
        );
        assert_eq!(d.total(), 4);
        assert_eq!(fix_differences(&live, &live).total(), 0);
        let mut other_type = fix(1, 0.1);
        other_type.fix_type = GnssFixType::Fix2d as u8;
        assert_eq!(fix_differences(&[other_type], &[fix(1, 0.1)]).total(), 2);
    }

    #[test]
    fn a_capture_scores_the_same_from_its_live_fixes_as_in_process() {
        let log = b"# Name: test\n$GPGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M,55.2,M,,*76\r\n";
        let bytes = replay::receiver_bytes(log);
        let (fixes, stats) = replay::decode(bytes);
        let link = GnssLinkReport {
            bytes: stats.bytes,
            sentences_used: stats.sentences,
            epochs: stats.epochs,
            ..GnssLinkReport::default()
        };
        let feed = LiveFeed {
            bytes_written: bytes.len() as u64,
            fixes: fixes.clone(),
            link: Some(link),
        };
        let (result, live) = evaluate_live("t.log", log, "", &feed);
        assert_eq!(
            result.score,
            super::super::evaluate_capture("t.log", log, "").score
        );
        assert_eq!(result.decoder.bytes, stats.bytes);
        assert_eq!(live.fixes_received, fixes.len());
        assert_eq!(live.live_vs_in_process_differences.total(), 0);
        assert!(!live.byte_mismatch());
        let report = build_live(vec![(result, live)], Vec::new(), 115_200);
        assert!(report.live_totals.without_link_report.is_empty());
        let short = LiveFeed {
            link: Some(GnssLinkReport { bytes: 3, ..link }),
            ..feed
        };
        let (_, lossy) = evaluate_live("t.log", log, "", &short);
        assert!(lossy.byte_mismatch());
        let json = serde_json::to_value(build_live(
            vec![evaluate_live("t.log", log, "", &short)],
            Vec::new(),
            9_600,
        ))
        .unwrap();
        assert_eq!(json["mode"], "live");
        assert_eq!(json["baud"], 9_600);
        assert_eq!(json["live"][0]["bytes_read_by_service"], 3);
        assert_eq!(json["live_totals"]["byte_mismatches"][0], "t.log");
        assert!(json["totals"]["captures"].is_u64());
    }
}
