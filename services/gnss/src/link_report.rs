//! The line report the gnss service publishes once a second: the decoder's counters under their
//! names, and whether the line is silent, that is carrying bytes of which nothing is usable.

use ipc_types::{GnssLinkReport, PAYLOAD_VERSION};
use rins_gnss_protocol::decode::GnssDecoderStats;

/// How long bytes may keep arriving without a used sentence or frame before the line counts as
/// silent, ns. Receivers rins reads send a position message at 1 Hz or faster, and even a 9600-baud
/// line completes the longest NMEA sentence in a tenth of a second: three seconds without one is
/// a receiver set to another protocol or baud rate, or noise, not a slow epoch.
pub const SILENT_AFTER_NS: u64 = 3_000_000_000;

/// Bytes since the last used message below which the line is not called silent: a stray byte or
/// a sentence's tail is not a receiver talking (the longest NMEA sentence is 82 bytes).
pub const SILENT_MIN_BYTES: u64 = 82;

/// What the service itself counts beside the decoder.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ServiceCounts {
    /// Epochs published.
    pub published: u64,
    /// Epochs that could not be published.
    pub publish_failures: u64,
    /// Times the device was reopened.
    pub reconnects: u64,
    /// No byte for the stale deadline.
    pub quiet: bool,
}

/// How the line's silence changed at a report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Silence {
    /// As it was.
    Unchanged,
    /// Bytes keep coming and none was usable for [`SILENT_AFTER_NS`].
    Began,
    /// A usable message arrived again.
    Ended,
}

/// Tracks the line's silence between reports.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SilentLine {
    /// Bytes read when a sentence or frame was last seen used (or when the tracking began).
    bytes_at_last_use: u64,
    /// When that was, ns; `None` before the first observation.
    last_use_ns: Option<u64>,
    /// Sentences and frames used at the last observation.
    used: u64,
    silent: bool,
    episodes: u64,
}

impl SilentLine {
    /// Judges the line from the decoder's counters at `now_ns`: silent while more than
    /// [`SILENT_MIN_BYTES`] arrived and no sentence or frame was used for [`SILENT_AFTER_NS`].
    pub fn observe(&mut self, stats: &GnssDecoderStats, now_ns: u64) -> Silence {
        let used = stats.sentences + stats.ubx_frames;
        if used != self.used || self.last_use_ns.is_none() {
            self.used = used;
            // The use may have come anywhere since the last observation: counting from now
            // errs towards not calling the line silent.
            self.bytes_at_last_use = stats.bytes;
            self.last_use_ns = Some(now_ns);
        }
        let since_ns = now_ns.saturating_sub(self.last_use_ns.unwrap_or(now_ns));
        let silent = since_ns >= SILENT_AFTER_NS
            && stats.bytes.saturating_sub(self.bytes_at_last_use) > SILENT_MIN_BYTES;
        let change = match (self.silent, silent) {
            (false, true) => {
                self.episodes += 1;
                Silence::Began
            }
            (true, false) => Silence::Ended,
            _ => Silence::Unchanged,
        };
        self.silent = silent;
        change
    }

    /// Silent at the last observation.
    pub fn silent(&self) -> bool {
        self.silent
    }

    /// Times the line became silent.
    pub fn episodes(&self) -> u64 {
        self.episodes
    }
}

/// The report of the decoder's `stats`, the service's own `counts` and the line's `silence`, made
/// at `now_ns`.
pub fn link_report(
    stats: &GnssDecoderStats,
    counts: &ServiceCounts,
    silence: &SilentLine,
    now_ns: u64,
) -> GnssLinkReport {
    let n = &stats.nmea;
    let f = &stats.framing;
    let unused_nmea = n.gsv + n.gsa + n.zda + n.txt + n.gbs + n.other + n.proprietary;
    GnssLinkReport {
        version: PAYLOAD_VERSION,
        heard: 1,
        silent: u8::from(silence.silent()),
        quiet: u8::from(counts.quiet),
        now_ns,
        bytes: stats.bytes,
        reconnects: counts.reconnects,
        sentences_used: stats.sentences,
        ubx_frames_used: stats.ubx_frames,
        unused_gsv: n.gsv,
        unused_gsa: n.gsa,
        unused_zda: n.zda,
        unused_txt: n.txt,
        unused_gbs: n.gbs,
        unused_other_nmea: n.other,
        unused_proprietary: n.proprietary,
        // The decoder's `unsupported` holds the unused NMEA kinds above and every other message.
        unused_other_messages: stats.unsupported.saturating_sub(unused_nmea),
        nothing_to_use: n.nothing_to_use,
        checksum_errors: stats.checksum_errors,
        without_checksum: n.without_checksum,
        malformed: stats.unparsable + stats.malformed,
        oversized: f.oversized,
        wrong_length: f.wrong_length,
        resyncs: f.resyncs,
        unframed_bytes: f.unframed_bytes,
        lines_crlf: f.lines_crlf,
        lines_lf: f.lines_lf,
        epochs: stats.epochs,
        epochs_without_fix: stats.epochs_without_fix,
        published: counts.published,
        publish_failures: counts.publish_failures,
        ubx_late: stats.ubx_late,
        nmea_epochs_superseded: stats.nmea_epochs_superseded,
        silent_episodes: silence.episodes(),
        ..GnssLinkReport::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_gnss_protocol::decode::GnssDecoder;

    fn stats_of(bytes: &[u8]) -> GnssDecoderStats {
        let mut d = GnssDecoder::new();
        d.push(bytes, 0, |_| {});
        d.stats()
    }

    const GGA: &[u8] = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47\r\n";

    const S: u64 = 1_000_000_000;

    #[test]
    fn a_line_of_noise_becomes_silent_once_and_recovers_when_sentences_come() {
        let mut line = SilentLine::default();
        let mut d = GnssDecoder::new();
        d.push(GGA, 0, |_| {});
        assert_eq!(line.observe(&d.stats(), 0), Silence::Unchanged);
        let noise = [0x55u8; 1000];
        d.push(&noise, 0, |_| {});
        // Noise, but not yet for long enough.
        assert_eq!(line.observe(&d.stats(), 2 * S), Silence::Unchanged);
        assert_eq!(line.observe(&d.stats(), 3 * S), Silence::Began);
        assert!(line.silent());
        d.push(&noise, 0, |_| {});
        assert_eq!(line.observe(&d.stats(), 4 * S), Silence::Unchanged);
        d.push(GGA, 0, |_| {});
        assert_eq!(line.observe(&d.stats(), 5 * S), Silence::Ended);
        assert_eq!(line.episodes(), 1);
    }

    #[test]
    fn a_quiet_line_or_a_stray_byte_is_not_silent() {
        let mut line = SilentLine::default();
        let mut d = GnssDecoder::new();
        assert_eq!(line.observe(&d.stats(), 0), Silence::Unchanged);
        assert_eq!(line.observe(&d.stats(), 10 * S), Silence::Unchanged);
        d.push(&[0x55; SILENT_MIN_BYTES as usize], 0, |_| {});
        assert_eq!(line.observe(&d.stats(), 20 * S), Silence::Unchanged);
        d.push(&[0x55], 0, |_| {});
        assert_eq!(line.observe(&d.stats(), 21 * S), Silence::Began);
    }

    #[test]
    fn sentences_without_a_checksum_make_a_silent_line() {
        let mut line = SilentLine::default();
        let sentence = b"$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,\r\n";
        let many: Vec<u8> = sentence.iter().copied().cycle().take(4 * 1024).collect();
        line.observe(&GnssDecoderStats::default(), 0);
        let stats = stats_of(&many);
        assert_eq!(line.observe(&stats, 3 * S), Silence::Began);
        let report = link_report(&stats, &ServiceCounts::default(), &line, 5);
        assert_eq!((report.silent, report.silent_episodes), (1, 1));
        assert_eq!(report.sentences_used, 0);
        assert!(report.without_checksum > 0 && report.checksum_errors >= report.without_checksum);
    }

    #[test]
    fn every_counter_lands_under_its_name() {
        let gsv = b"$GPGSV,1,1,01,01,40,083,46*44\r\n";
        let bytes = [GGA, gsv, b"$PGRME,15.0,M,45.0,M,25.0,M*1C\r\n", b"junk"].concat();
        let stats = stats_of(&bytes);
        let counts = ServiceCounts {
            published: 2,
            publish_failures: 1,
            reconnects: 3,
            quiet: true,
        };
        let r = link_report(&stats, &counts, &SilentLine::default(), 42);
        assert_eq!(
            (r.version, r.heard, r.silent, r.quiet),
            (PAYLOAD_VERSION, 1, 0, 1)
        );
        assert_eq!((r.now_ns, r.bytes), (42, bytes.len() as u64));
        assert_eq!(
            (r.sentences_used, r.unused_gsv, r.unused_proprietary),
            (1, 1, 1)
        );
        assert_eq!((r.published, r.publish_failures, r.reconnects), (2, 1, 3));
        assert_eq!((r.lines_crlf, r.lines_lf), (3, 0));
        assert_eq!(r.unused_other_messages, 0);
    }
}
