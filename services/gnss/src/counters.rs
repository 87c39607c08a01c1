//! The decoder's counts as the heartbeat carries them.

use ipc_types::Health;
use rins_gnss_protocol::decode::GnssDecoderStats;

/// Fills the heartbeat's counters from the decoder's: epochs are the frames received and
/// published; checksum failures the CRC errors; unreadable and implausible messages the
/// malformed ones.
pub fn fill(counters: &mut Health, stats: &GnssDecoderStats, published: u64) {
    counters.received = stats.epochs;
    counters.published = published;
    counters.valid_frames = stats.sentences + stats.ubx_frames;
    counters.crc_errors = stats.checksum_errors;
    counters.malformed = stats.unparsable + stats.malformed;
    counters.bytes_received = stats.bytes;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_count_lands_in_its_field() {
        let stats = GnssDecoderStats {
            bytes: 1000,
            sentences: 8,
            ubx_frames: 2,
            checksum_errors: 3,
            unparsable: 4,
            unsupported: 9,
            malformed: 5,
            epochs: 6,
            epochs_without_fix: 1,
            ..GnssDecoderStats::default()
        };
        let mut h = Health::default();
        fill(&mut h, &stats, 6);
        assert_eq!(
            (
                h.received,
                h.published,
                h.valid_frames,
                h.crc_errors,
                h.malformed,
                h.bytes_received
            ),
            (6, 6, 10, 3, 9, 1000)
        );
    }
}
