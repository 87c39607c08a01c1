//! The receiver's byte stream → one [`GnssFix`] per receiver epoch.
//!
//! A u-blox receiver may send UBX frames and NMEA sentences on the same line; [`framer`] finds
//! both (and skips what is neither), the `ublox` crate reads the frames, [`NmeaEpoch`] the
//! sentences. This module assembles epochs, checks that the values are plausible (a valid
//! checksum does not make a latitude of 400° sane), and counts everything it set aside.

mod ecef;
mod epoch_source;
pub mod framer;
mod nmea_epoch;
mod nmea_fields;
mod nmea_reading;
mod nmea_sentence;
mod sanity;
mod ubx_epoch;
mod ubx_fix_type;
mod ubx_hnr_pvt;
mod ubx_pvt;
mod ubx_sol;

use framer::{Framed, Framer};
use ipc_types::{GnssFix, Stage};
use ublox::UbxProtocol;
use ublox::proto23::Proto23;

pub use epoch_source::EpochSource;
pub use nmea_epoch::{EPOCH_QUIET_NS, NmeaEpoch, SAME_EPOCH_US, SentenceOutcome};
pub use nmea_sentence::NmeaStats;
pub use sanity::is_plausible;
pub use ubx_epoch::{FrameOutcome, UbxEpoch};
pub use ubx_pvt::fix_from_nav_pvt;

/// What the decoder took in and set aside since it started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct GnssDecoderStats {
    /// Bytes taken in.
    pub bytes: u64,
    /// NMEA sentences with a good checksum that were used (GGA, GNS, RMC, GLL, GST, VTG, GSA).
    pub sentences: u64,
    /// UBX navigation frames taken into an epoch (NAV-PVT, HNR-PVT, NAV-SOL, NAV-POSLLH,
    /// NAV-VELNED, NAV-DOP, NAV-EOE; see [`UbxEpoch`]).
    pub ubx_frames: u64,
    /// NMEA sentences or UBX frames whose checksum did not match.
    pub checksum_errors: u64,
    /// NMEA sentences the parser could not read, and UBX frames it refused.
    pub unparsable: u64,
    /// Well-formed messages of other kinds (GSV, ZDA, other UBX classes, `!` encapsulation
    /// sentences such as AIS): passed by.
    pub unsupported: u64,
    /// Messages whose values are out of range or not numbers, and UBX headers declaring a length
    /// no accepted message has (see [`framer::MAX_UBX_PAYLOAD`]): not used.
    pub malformed: u64,
    /// Epochs published.
    pub epochs: u64,
    /// Epochs without a three-dimensional fix.
    pub epochs_without_fix: u64,
    /// UBX frames of an epoch older than the one being assembled (HNR-PVT running ahead of
    /// NAV-PVT, say): that epoch was handed out already, so they are not published again.
    pub ubx_late: u64,
    /// NMEA epochs not published because the receiver sends UBX epochs too: one fix per epoch,
    /// UBX preferred (see [`EpochSource`]). Their sentences count as used.
    pub nmea_epochs_superseded: u64,
    /// What the framer passed over (bytes in no sentence or frame, dropped sentence starts,
    /// refused UBX headers) and how the sentences ended.
    pub framing: framer::FramingStats,
    /// NMEA sentences passed by, by kind, and NMEA epochs not published.
    pub nmea: NmeaStats,
}

impl GnssDecoderStats {
    /// Bytes came in but no sentence or frame was used: whatever is on the line, rins reads
    /// nothing of it.
    pub fn silent(&self) -> bool {
        self.bytes > 0 && self.sentences == 0 && self.ubx_frames == 0
    }
}

/// Streaming decoder of a GNSS receiver's output. Allocation-free.
#[derive(Default)]
pub struct GnssDecoder {
    framer: Framer,
    nmea: NmeaEpoch,
    ubx: UbxEpoch,
    source: EpochSource,
    seq: u64,
    stats: GnssDecoderStats,
    /// Receive time of the last UBX frame taken into an epoch, ns.
    ubx_last_rx_ns: u64,
}

impl GnssDecoder {
    /// A decoder that has seen nothing.
    pub fn new() -> Self {
        Self::default()
    }

    /// What it took in and set aside so far.
    pub fn stats(&self) -> GnssDecoderStats {
        GnssDecoderStats {
            framing: self.framer.stats(),
            nmea: self.nmea.stats(),
            ..self.stats
        }
    }

    /// Hands out the epochs still being assembled, complete or not, with the receive time of
    /// their last message (NMEA) or `rx_ns` (UBX): at the end of the receiver's output, so that
    /// its last epoch is not lost.
    pub fn flush(&mut self, rx_ns: u64, mut on_epoch: impl FnMut(GnssFix)) {
        let ubx = self.ubx.flush();
        let nmea = self.nmea.flush();
        self.publish_pending(ubx, nmea, rx_ns, &mut on_epoch);
    }

    /// Hands out an NMEA or UBX epoch the receiver has sent nothing for since a second
    /// (`EPOCH_QUIET_NS`) before `now_ns`, complete or not (a message of it was lost and the
    /// receiver went quiet), stamped with the receive time of its last message. [`Self::push`]
    /// does this first.
    pub fn close_quiet(&mut self, now_ns: u64, mut on_epoch: impl FnMut(GnssFix)) {
        let nmea = self.nmea.close_quiet(now_ns);
        let ubx_quiet = now_ns >= self.ubx_last_rx_ns.saturating_add(EPOCH_QUIET_NS);
        let ubx = if ubx_quiet { self.ubx.flush() } else { None };
        self.publish_pending(ubx, nmea, self.ubx_last_rx_ns, &mut on_epoch);
    }

    fn publish_pending(
        &mut self,
        ubx: Option<GnssFix>,
        nmea: Option<GnssFix>,
        rx_ns: u64,
        on_epoch: &mut impl FnMut(GnssFix),
    ) {
        if let Some(fix) = ubx {
            self.source.ubx_published();
            on_epoch(stamp(fix, rx_ns, &mut self.seq, &mut self.stats));
        }
        if let Some(fix) = nmea {
            if self.source.publish_nmea() {
                let rx_ns = fix.header.origin_rx_ns;
                on_epoch(stamp(fix, rx_ns, &mut self.seq, &mut self.stats));
            } else {
                self.stats.nmea_epochs_superseded += 1;
            }
        }
    }

    /// Takes `bytes` received at `rx_ns` (CLOCK_MONOTONIC) and hands every completed epoch to
    /// `on_epoch`, stamped with the receive time of its last message and the next sequence
    /// number.
    pub fn push(&mut self, bytes: &[u8], rx_ns: u64, mut on_epoch: impl FnMut(GnssFix)) {
        self.close_quiet(rx_ns, &mut on_epoch);
        self.stats.bytes += bytes.len() as u64;
        let Self {
            framer,
            nmea,
            ubx,
            source,
            seq,
            stats,
            ubx_last_rx_ns,
        } = self;
        let mut emit = |fix: GnssFix, rx_ns: u64, stats: &mut GnssDecoderStats| {
            on_epoch(stamp(fix, rx_ns, seq, stats));
        };
        framer.push(bytes, |item| match item {
            Framed::Ubx { class, id, payload } => {
                let mut padded = [0u8; framer::NAV_PVT_LEN];
                let payload = pad_proto14_nav_pvt(class, id, payload, &mut padded);
                match <Proto23 as UbxProtocol>::match_packet(class, id, payload) {
                    Ok(packet) => match ubx.push(&packet) {
                        FrameOutcome::Used { closed, completed } => {
                            stats.ubx_frames += 1;
                            *ubx_last_rx_ns = rx_ns;
                            for fix in [closed, completed].into_iter().flatten() {
                                source.ubx_published();
                                emit(fix, rx_ns, stats);
                            }
                        }
                        FrameOutcome::Late => stats.ubx_late += 1,
                        FrameOutcome::Malformed => stats.malformed += 1,
                        FrameOutcome::Unsupported => stats.unsupported += 1,
                    },
                    Err(_) => stats.unparsable += 1,
                }
            }
            Framed::UbxChecksum => stats.checksum_errors += 1,
            Framed::UbxBadLength => stats.malformed += 1,
            Framed::Encapsulated { checksum_ok, .. } => match checksum_ok {
                true => stats.unsupported += 1,
                false => stats.checksum_errors += 1,
            },
            Framed::Nmea(sentence) => match nmea.push(sentence, rx_ns) {
                SentenceOutcome::Used { closed, completed } => {
                    stats.sentences += 1;
                    for fix in [closed, completed].into_iter().flatten() {
                        // Stamped with the receive time of the epoch's last sentence.
                        if source.publish_nmea() {
                            emit(fix, fix.header.origin_rx_ns, stats);
                        } else {
                            stats.nmea_epochs_superseded += 1;
                        }
                    }
                }
                SentenceOutcome::Checksum | SentenceOutcome::WithoutChecksum => {
                    stats.checksum_errors += 1
                }
                SentenceOutcome::Unparsable => stats.unparsable += 1,
                SentenceOutcome::Unsupported => stats.unsupported += 1,
                SentenceOutcome::Malformed => stats.malformed += 1,
            },
        });
    }
}

/// `payload`, or a protocol 14 NAV-PVT's 84 bytes copied into `padded` (its later fields
/// headVeh, magDec, magAcc zero, unused by the decoder): the parser reads the 92-byte form only.
fn pad_proto14_nav_pvt<'a>(
    class: u8,
    id: u8,
    payload: &'a [u8],
    padded: &'a mut [u8; framer::NAV_PVT_LEN],
) -> &'a [u8] {
    if (class, id) != (0x01, 0x07) || payload.len() != framer::NAV_PVT_PROTO14_LEN {
        return payload;
    }
    padded[..payload.len()].copy_from_slice(payload);
    padded
}

/// `fix` stamped with its receive time and the next sequence number, and counted.
fn stamp(mut fix: GnssFix, rx_ns: u64, seq: &mut u64, stats: &mut GnssDecoderStats) -> GnssFix {
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
    fix
}
