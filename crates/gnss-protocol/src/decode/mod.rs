//! The receiver's byte stream → one [`GnssFix`] per receiver epoch.
//!
//! A u-blox receiver may send UBX frames and NMEA sentences on the same line; [`framer`] finds
//! both (and skips what is neither), the `ublox` crate reads the frames, the `nmea` crate the
//! sentences. This module assembles epochs, checks that the values are plausible (a valid
//! checksum does not make a latitude of 400° sane), and counts everything it set aside.

pub mod framer;
mod nmea_epoch;
mod sanity;
mod ubx_pvt;

use framer::{Framed, Framer};
use ipc_types::{GnssFix, Stage};
use ublox::UbxProtocol;
use ublox::proto23::{PacketRef, Proto23};

pub use nmea_epoch::{NmeaEpoch, SentenceOutcome};
pub use sanity::is_plausible;
pub use ubx_pvt::fix_from_nav_pvt;

/// What the decoder took in and set aside since it started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GnssDecoderStats {
    /// Bytes taken in.
    pub bytes: u64,
    /// NMEA sentences with a good checksum that were used (GGA, RMC, GST, VTG).
    pub sentences: u64,
    /// UBX NAV-PVT frames used.
    pub ubx_frames: u64,
    /// NMEA sentences or UBX frames whose checksum did not match.
    pub checksum_errors: u64,
    /// NMEA sentences the parser could not read, and UBX frames it refused.
    pub unparsable: u64,
    /// Well-formed messages of other kinds (GSV, GSA, other UBX classes): passed by.
    pub unsupported: u64,
    /// Messages whose values are out of range or not numbers, and UBX headers declaring a length
    /// no accepted message has (see [`framer::MAX_UBX_PAYLOAD`]): not used.
    pub malformed: u64,
    /// Epochs published.
    pub epochs: u64,
    /// Epochs without a three-dimensional fix.
    pub epochs_without_fix: u64,
}

/// Streaming decoder of a GNSS receiver's output. Allocation-free.
#[derive(Default)]
pub struct GnssDecoder {
    framer: Framer,
    nmea: NmeaEpoch,
    seq: u64,
    stats: GnssDecoderStats,
}

impl GnssDecoder {
    /// A decoder that has seen nothing.
    pub fn new() -> Self {
        Self::default()
    }

    /// What it took in and set aside so far.
    pub fn stats(&self) -> GnssDecoderStats {
        self.stats
    }

    /// Takes `bytes` received at `rx_ns` (CLOCK_MONOTONIC) and hands every completed epoch to
    /// `on_epoch`, stamped with that receive time and the next sequence number.
    pub fn push(&mut self, bytes: &[u8], rx_ns: u64, mut on_epoch: impl FnMut(GnssFix)) {
        self.stats.bytes += bytes.len() as u64;
        let Self {
            framer,
            nmea,
            seq,
            stats,
        } = self;
        let mut emit = |mut fix: GnssFix, stats: &mut GnssDecoderStats| {
            *seq += 1;
            fix.header.origin_seq = *seq;
            fix.header.origin_rx_ns = rx_ns;
            fix.header.origin_device_time_us = 0;
            fix.header.stage_pub_ns[Stage::Acquisition as usize] = 0;
            stats.epochs += 1;
            let has_fix = ipc_types::GnssFixType::from_u8(fix.fix_type).is_some_and(|t| t.is_3d());
            if !has_fix {
                stats.epochs_without_fix += 1;
            }
            on_epoch(fix);
        };
        framer.push(bytes, |item| match item {
            Framed::Ubx { class, id, payload } => {
                match <Proto23 as UbxProtocol>::match_packet(class, id, payload) {
                    Ok(PacketRef::NavPvt(pvt)) => {
                        let fix = fix_from_nav_pvt(&pvt);
                        if is_plausible(&fix) {
                            stats.ubx_frames += 1;
                            emit(fix, stats);
                        } else {
                            stats.malformed += 1;
                        }
                    }
                    Ok(_) => stats.unsupported += 1,
                    Err(_) => stats.unparsable += 1,
                }
            }
            Framed::UbxChecksum => stats.checksum_errors += 1,
            Framed::UbxBadLength => stats.malformed += 1,
            Framed::Nmea(sentence) => match nmea.push(sentence) {
                SentenceOutcome::Used(done) => {
                    stats.sentences += 1;
                    if let Some(fix) = done {
                        emit(fix, stats);
                    }
                }
                SentenceOutcome::Checksum => stats.checksum_errors += 1,
                SentenceOutcome::Unparsable => stats.unparsable += 1,
                SentenceOutcome::Unsupported => stats.unsupported += 1,
                SentenceOutcome::Malformed => stats.malformed += 1,
            },
        });
    }
}
