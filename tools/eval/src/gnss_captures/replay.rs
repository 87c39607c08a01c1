//! A capture's bytes played through the product's GNSS decoder as a serial line would deliver
//! them.

use ipc_types::GnssFix;
use rins_gnss_protocol::decode::framer::{Framed, Framer};
use rins_gnss_protocol::decode::{GnssDecoder, GnssDecoderStats};
use serde::Serialize;

/// Bytes per read: what a serial read returns from a busy line (the kernel's tty layer hands
/// over what arrived, typically tens of bytes).
pub const CHUNK_BYTES: usize = 64;
/// Line time of one byte at 9600 baud, 8N1 (10 bits): the rate most of these receivers send
/// NMEA at. The receive time of a read is that of its last byte.
pub const NS_PER_BYTE: u64 = 1_041_667;

/// The receiver's bytes of a capture file: what follows the leading `#` comment lines (name,
/// chipset, submitter, licence).
pub fn receiver_bytes(log: &[u8]) -> &[u8] {
    let mut rest = log;
    while rest.first() == Some(&b'#') {
        rest = match rest.iter().position(|&b| b == b'\n') {
            Some(end) => &rest[end + 1..],
            None => &[],
        };
    }
    rest
}

/// Which protocols the bytes carry, independent of what the decoder uses of them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct ProtocolsSeen {
    /// NMEA position sentences (GGA, RMC, GNS, GLL of any talker) framed with a good checksum or
    /// none.
    pub nmea_position_sentences: u64,
    /// UBX frames with a good checksum.
    pub ubx_frames: u64,
}

/// How a capture is grouped in the totals.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ProtocolGroup {
    /// NMEA position sentences, no UBX.
    NmeaOnly,
    /// UBX frames, no NMEA position sentences.
    UbxOnly,
    /// Both.
    Mixed,
    /// Neither.
    Neither,
}

impl ProtocolsSeen {
    /// The group of a capture carrying these.
    pub fn group(self) -> ProtocolGroup {
        match (self.nmea_position_sentences > 0, self.ubx_frames > 0) {
            (true, false) => ProtocolGroup::NmeaOnly,
            (false, true) => ProtocolGroup::UbxOnly,
            (true, true) => ProtocolGroup::Mixed,
            (false, false) => ProtocolGroup::Neither,
        }
    }
}

/// Counts what the bytes carry (with the product's framer, so "UBX frame" means the same as in
/// the decoder).
pub fn protocols_seen(bytes: &[u8]) -> ProtocolsSeen {
    let mut seen = ProtocolsSeen::default();
    let mut framer = Box::<Framer>::default();
    framer.push(bytes, |item| match item {
        Framed::Ubx { .. } => seen.ubx_frames += 1,
        Framed::Nmea(sentence) if is_position_sentence(sentence) => {
            seen.nmea_position_sentences += 1;
        }
        // Bad frames, other sentences, and whatever else the framer reports.
        _ => {}
    });
    seen
}

/// `$ttGGA,`, `$ttRMC,`, `$ttGNS,` or `$ttGLL,` for any two-letter talker.
fn is_position_sentence(sentence: &[u8]) -> bool {
    sentence.len() > 7
        && sentence[6] == b','
        && matches!(&sentence[3..6], b"GGA" | b"RMC" | b"GNS" | b"GLL")
}

/// Every fix the decoder publishes from `bytes`, read [`CHUNK_BYTES`] at a time at the line rate
/// of [`NS_PER_BYTE`] and flushed at the end, and its counters then.
pub fn decode(bytes: &[u8]) -> (Vec<GnssFix>, GnssDecoderStats) {
    let mut decoder = Box::<GnssDecoder>::default();
    let mut fixes = Vec::new();
    let mut received = 0_u64;
    for chunk in bytes.chunks(CHUNK_BYTES) {
        received += chunk.len() as u64;
        decoder.push(chunk, received * NS_PER_BYTE, |fix| fixes.push(fix));
    }
    // The capture ends: the epoch still being assembled is the receiver's last.
    decoder.flush(received * NS_PER_BYTE, |fix| fixes.push(fix));
    (fixes, decoder.stats())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comment_lines_are_not_receiver_bytes() {
        let log = b"# Name: x\n# Chipset: y\r\n#\n$GPGGA,1*00\r\n# not a header\n";
        assert_eq!(receiver_bytes(log), b"$GPGGA,1*00\r\n# not a header\n");
        assert_eq!(receiver_bytes(b"# only a comment"), b"");
        assert_eq!(receiver_bytes(b"\xb5\x62"), b"\xb5\x62");
    }

    #[test]
    fn position_sentences_of_any_talker_and_ubx_frames_are_seen() {
        // A UBX ACK-ACK (class 5, id 1, payload 06 01) with its checksum.
        let ack: &[u8] = &[0xB5, 0x62, 0x05, 0x01, 0x02, 0x00, 0x06, 0x01, 0x0F, 0x38];
        let mut bytes = Vec::new();
        bytes.extend_from_slice(b"$INRMC,1*00\r\n$GPGSV,1*00\r\n$ECGLL,2*00\r\n");
        bytes.extend_from_slice(ack);
        bytes.extend_from_slice(b"$GNGNS,3*00\r\n");
        let seen = protocols_seen(&bytes);
        assert_eq!(
            seen,
            ProtocolsSeen {
                nmea_position_sentences: 3,
                ubx_frames: 1
            }
        );
        assert_eq!(seen.group(), ProtocolGroup::Mixed);
        assert_eq!(protocols_seen(b"noise").group(), ProtocolGroup::Neither);
    }

    #[test]
    fn decoding_counts_every_byte() {
        let line = b"$GPGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M,55.2,M,,*76\r\n";
        let bytes: Vec<u8> = line.iter().copied().cycle().take(line.len() * 3).collect();
        let (_, stats) = decode(&bytes);
        assert_eq!(stats.bytes, bytes.len() as u64);
        assert_eq!(stats.sentences, 3);
    }
}
