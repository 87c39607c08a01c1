//! What `rins probe --gnss` makes of a receiver's line: the epochs and their fixes, the last fix,
//! the verdict that names the situation, and the best rate of a scan. Pure: listening to the
//! device is `probe_gnss`'s part.

use ipc_types::{GnssFix, GnssFixType, GnssProtocol};
use rins_gnss::link_report::{ServiceCounts, SilentLine, link_report};
use rins_gnss_protocol::decode::GnssDecoderStats;
use rins_watchdog::gnss_line::GnssRow;

/// Microseconds in a day: an NMEA fix's time is the UTC time of day.
const US_PER_DAY: u64 = 86_400_000_000;

/// What an epoch says of the receiver's position.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FixClass {
    /// Three-dimensional (plain, differential or RTK).
    ThreeD,
    /// Horizontal only.
    TwoD,
    /// No satellite position (none, or the receiver's own dead reckoning).
    None,
}

impl FixClass {
    /// The class of a fix of type `fix_type` (a [`GnssFixType`] as u8; an unknown value is none).
    pub fn of(fix_type: u8) -> Self {
        match GnssFixType::from_u8(fix_type) {
            Some(t) if t.is_3d() => Self::ThreeD,
            Some(GnssFixType::Fix2d) => Self::TwoD,
            _ => Self::None,
        }
    }
}

/// The epochs the decoder published during a listen. Fed once per epoch; does not allocate.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct EpochTally {
    /// Epochs published.
    pub epochs: u64,
    /// Of them with a three-dimensional fix.
    pub fix_3d: u64,
    /// Of them with a two-dimensional fix.
    pub fix_2d: u64,
    /// Of them without a satellite position.
    pub no_fix: u64,
    /// The first epoch with a position (2-D or 3-D).
    pub first_fix: Option<GnssFix>,
    /// The last epoch with a position.
    pub last_fix: Option<GnssFix>,
}

impl EpochTally {
    /// Counts one published epoch.
    pub fn observe(&mut self, fix: &GnssFix) {
        self.epochs += 1;
        match FixClass::of(fix.fix_type) {
            FixClass::ThreeD => self.fix_3d += 1,
            FixClass::TwoD => self.fix_2d += 1,
            FixClass::None => {
                self.no_fix += 1;
                return;
            }
        }
        if self.first_fix.is_none() {
            self.first_fix = Some(*fix);
        }
        self.last_fix = Some(*fix);
    }

    /// Epochs with a position.
    pub fn fixes(&self) -> u64 {
        self.fix_3d + self.fix_2d
    }

    /// Fixes per second by their arrival (receive times of the first and last fix), Hz; `None`
    /// with fewer than two fixes.
    pub fn arrival_hz(&self) -> Option<f64> {
        let (first, last) = (self.first_fix?, self.last_fix?);
        let span_ns = last
            .header
            .origin_rx_ns
            .checked_sub(first.header.origin_rx_ns)?;
        rate(self.fixes(), span_ns as f64 * 1e-9)
    }

    /// Fixes per second by the receiver's own clock (the times of the first and last fix), Hz:
    /// the receiver's solution rate, however the line delivered them. `None` with fewer than two
    /// fixes, fixes of two protocols, or a span across midnight (NMEA) or a week's end (UBX).
    pub fn receiver_hz(&self) -> Option<f64> {
        let (first, last) = (self.first_fix?, self.last_fix?);
        if first.protocol != last.protocol {
            return None;
        }
        let span_us = last.receiver_time_us.checked_sub(first.receiver_time_us)?;
        if span_us >= US_PER_DAY {
            return None;
        }
        rate(self.fixes(), span_us as f64 * 1e-6)
    }

    /// The fix rate the verdict states: the receiver's own where it can be told, else by arrival.
    pub fn fix_hz(&self) -> Option<f64> {
        self.receiver_hz().or_else(|| self.arrival_hz())
    }
}

/// `count` events over `span_s` seconds from the first to the last: (count − 1) / span.
fn rate(count: u64, span_s: f64) -> Option<f64> {
    (count >= 2 && span_s > 0.0).then(|| (count - 1) as f64 / span_s)
}

/// Everything one listen to a receiver's line gave.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GnssLineReport {
    /// How long the line was listened to, s.
    pub seconds: f64,
    /// The decoder's counters at the end.
    pub stats: GnssDecoderStats,
    /// The epochs it published.
    pub tally: EpochTally,
}

impl GnssLineReport {
    /// Bytes per second on the line.
    pub fn bytes_per_s(&self) -> f64 {
        self.stats.bytes as f64 / self.seconds
    }

    /// NMEA sentences and UBX frames the decoder used: what a scan ranks rates by.
    pub fn used(&self) -> u64 {
        self.stats.sentences + self.stats.ubx_frames
    }

    /// The protocols on the line: NMEA where sentences were framed (used or not), UBX where
    /// frames were used or published an epoch.
    pub fn protocols(&self) -> Vec<&'static str> {
        let s = &self.stats;
        let mut seen = Vec::new();
        if s.sentences > 0 || s.framing.lines_crlf + s.framing.lines_lf > 0 {
            seen.push("NMEA");
        }
        if s.ubx_frames > 0 {
            seen.push("UBX");
        }
        seen
    }

    /// One line that names the situation and what to check.
    pub fn verdict(&self) -> String {
        let s = &self.stats;
        if s.bytes == 0 {
            return format!(
                "no bytes at all in {:.1} s: is this the receiver's device, is the receiver \
                 powered and connected?",
                self.seconds
            );
        }
        if s.silent() {
            return format!(
                "silent line: {} bytes but no usable NMEA sentence or UBX frame: likely a wrong \
                 baud rate or a protocol rins does not read; {}",
                s.bytes,
                dominant_problem(s)
            );
        }
        let protocols = self.protocols().join(" + ");
        let t = &self.tally;
        if t.fixes() == 0 {
            let mut used = Vec::new();
            if s.sentences > 0 {
                used.push(format!("{} NMEA sentences", s.sentences));
            }
            if s.ubx_frames > 0 {
                used.push(format!("{} UBX frames", s.ubx_frames));
            }
            return format!(
                "receiver without a fix: {} used, {} epochs, none with a position: give the \
                 antenna a clear view of the sky and wait",
                used.join(" and "),
                t.epochs
            );
        }
        let hz = t
            .fix_hz()
            .map_or_else(|| "one fix".to_string(), |hz| format!("{hz:.1} Hz"));
        let mut line = format!(
            "fixes flowing: {hz} over {protocols}, {} of {} epochs 3-D",
            t.fix_3d, t.epochs
        );
        if t.fix_2d > 0 {
            line.push_str(&format!(", {} 2-D", t.fix_2d));
        }
        if t.fix_3d == 0 {
            line.push_str(" (2-D only: the receiver sees too few satellites for a height)");
        }
        line
    }
}

/// What dominates a silent line, in words an operator acts on.
fn dominant_problem(s: &GnssDecoderStats) -> String {
    let without_checksum = s.nmea.without_checksum;
    let checksum_failures = s.checksum_errors.saturating_sub(without_checksum);
    let messages = [
        (
            checksum_failures,
            "checksum failures: the bytes arrive garbled (baud rate?)",
        ),
        (
            without_checksum,
            "sentences without checksum: enable checksums on the receiver",
        ),
        (
            s.malformed,
            "malformed sentences or frames: values out of range",
        ),
        (
            s.unparsable,
            "sentences or frames the parser could not read",
        ),
        (
            s.unsupported,
            "only messages rins does not use (GSV, GSA, other UBX classes): enable GGA/RMC or \
             UBX NAV-PVT on the receiver",
        ),
    ];
    let top = messages
        .into_iter()
        .max_by_key(|(count, _)| *count)
        .filter(|(count, _)| *count > 0);
    let unframed_share = s.framing.unframed_bytes as f64 / s.bytes as f64;
    match top {
        Some((count, what)) if unframed_share < 0.5 => format!("mostly {count} {what}"),
        _ => format!(
            "mostly unframed bytes ({} of {}, {} resyncs): no NMEA or UBX framing",
            s.framing.unframed_bytes, s.bytes, s.framing.resyncs
        ),
    }
}

/// The rate of a scan with the most used sentences and frames (the first of equals); `None`
/// where no rate gave one.
pub fn best_rate(used_by_rate: impl IntoIterator<Item = (u32, u64)>) -> Option<u32> {
    let mut best: Option<(u32, u64)> = None;
    for (baud, used) in used_by_rate {
        if used > best.map_or(0, |(_, b)| b) {
            best = Some((baud, used));
        }
    }
    best.map(|(baud, _)| baud)
}

/// The one-line verdict of a scan.
pub fn scan_verdict(results: &[(u32, GnssLineReport)]) -> String {
    match best_rate(results.iter().map(|(baud, r)| (*baud, r.used()))) {
        Some(baud) => {
            let used = results
                .iter()
                .find(|(b, _)| *b == baud)
                .map_or(0, |(_, r)| r.used());
            format!("receiver at {baud} baud: {used} sentences/frames used there")
        }
        None if results.iter().all(|(_, r)| r.stats.bytes == 0) => {
            "no bytes at any rate: is this the receiver's device, is the receiver powered and \
             connected?"
                .into()
        }
        None => "bytes but no usable sentence or frame at any rate: a protocol rins does not \
                 read, or a rate not tried"
            .into(),
    }
}

/// A fix's time as the receiver gave it: UTC time of day (NMEA) or GPS time of week (UBX).
pub fn receiver_time_text(fix: &GnssFix) -> String {
    let us = fix.receiver_time_us;
    if fix.protocol == GnssProtocol::Ubx as u8 {
        return format!("GPS time of week {:.3} s", us as f64 * 1e-6);
    }
    let ms = (us % US_PER_DAY) / 1_000;
    format!(
        "{:02}:{:02}:{:02}.{:03} UTC",
        ms / 3_600_000,
        ms / 60_000 % 60,
        ms / 1_000 % 60,
        ms % 1_000
    )
}

/// The counters that only a running gnss service has (publication, reconnection, the silence it
/// tracks over time): not part of a probe's report.
const SERVICE_ONLY: [&str; 4] = [
    "published",
    "publish_failures",
    "reconnects",
    "silent_episodes",
];

/// Every counter of the line by name, sorted by name: the names the gnss service's line report
/// (`rins status`, `rins echo gnss-link`) uses, so that a probe and a running service read alike.
pub fn counters(stats: &GnssDecoderStats) -> Vec<(String, u64)> {
    let report = link_report(stats, &ServiceCounts::default(), &SilentLine::default(), 0);
    let Ok(serde_json::Value::Object(map)) = serde_json::to_value(GnssRow(report)) else {
        return Vec::new();
    };
    map.into_iter()
        .filter(|(name, _)| !SERVICE_ONLY.contains(&name.as_str()))
        .filter_map(|(name, v)| v.as_u64().map(|n| (name, n)))
        .collect()
}

#[cfg(test)]
#[path = "probe_gnss_report_tests.rs"]
mod tests;
