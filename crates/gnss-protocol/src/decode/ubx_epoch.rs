//! UBX navigation messages of one receiver epoch put together into one fix.
//!
//! Every UBX navigation message carries the epoch's GPS time of week (iTOW, ms): messages of one
//! iTOW are one epoch. NAV-PVT and HNR-PVT are each a whole solution: the first of them makes
//! the epoch's fix at once. Receivers without them send NAV-SOL, NAV-POSLLH, NAV-VELNED and
//! NAV-DOP (see [`super::ubx_sol`]); such an epoch is complete when every one of these the
//! receiver sent in its previous epoch is in, or when NAV-EOE (end of epoch) says so, so that a
//! fix is not held back a whole period waiting for the next epoch's first message. An epoch
//! left incomplete (a message lost), and the very first one (before the decoder knows what this
//! receiver sends), is published when a message of another iTOW arrives, at NAV-EOE or at
//! [`UbxEpoch::flush`].
//!
//! One epoch, one fix: a message of an epoch already published adds nothing. A message of an
//! epoch up to [`LATE_WINDOW_MS`] older than the one in progress (HNR-PVT at a high rate
//! running ahead of NAV-PVT) is late and not used; an iTOW further back is a new epoch (the
//! receiver restarted, or the week rolled over).

use ipc_types::{GnssFix, GnssFixType, GnssProtocol, PAYLOAD_VERSION};
use ublox::proto23::PacketRef;

use super::sanity::is_plausible;
use super::ubx_hnr_pvt::fix_from_hnr_pvt;
use super::ubx_pvt::fix_from_nav_pvt;
use super::ubx_sol::{PosLlh, VelNed, fix_from_nav_sol, hdop};

/// How far back (ms) a message's iTOW may be from the epoch in progress and still count as late
/// rather than as a new epoch: more than any latency between a receiver's messages of one
/// epoch, far less than a restart's jump.
pub const LATE_WINDOW_MS: u32 = 1_000;

/// Milliseconds in a GPS week: iTOW wraps there.
const WEEK_MS: i64 = 604_800_000;

/// Kinds of messages of an epoch, as bits of a set.
const PVT: u8 = 1 << 0;
const SOL: u8 = 1 << 1;
const POSLLH: u8 = 1 << 2;
const VELNED: u8 = 1 << 3;
const DOP: u8 = 1 << 4;
/// The kinds that carry a position.
const POSITION: u8 = PVT | SOL | POSLLH;

/// What became of one UBX frame.
// Handed back by value and never stored: boxing the fixes would allocate per frame.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrameOutcome {
    /// Taken into an epoch; with the fix of an epoch it closed and of one it completed (at most
    /// one each, in that order).
    Used {
        /// The fix of the earlier epoch this frame closed.
        closed: Option<GnssFix>,
        /// The fix of the epoch this frame completed.
        completed: Option<GnssFix>,
    },
    /// A navigation message of an epoch older than the one in progress: not used.
    Late,
    /// A navigation message whose values are out of range: not used.
    Malformed,
    /// A message of another kind.
    Unsupported,
}

/// One message's contribution to its epoch.
enum Part {
    Pvt(GnssFix),
    Sol(GnssFix),
    PosLlh(PosLlh),
    VelNed(VelNed),
    Dop(f64),
    EndOfEpoch,
}

/// The epoch being assembled. Allocation-free.
#[derive(Debug, Clone, Copy, Default)]
pub struct UbxEpoch {
    itow_ms: Option<u32>,
    pvt: Option<GnssFix>,
    sol: Option<GnssFix>,
    pos_llh: Option<PosLlh>,
    vel_ned: Option<VelNed>,
    hdop: Option<f64>,
    /// Kinds of messages in so far.
    have: u8,
    /// Already handed out: later messages of the same iTOW are not a new epoch.
    published: bool,
    /// Kinds the receiver sent in its last whole epoch.
    sends: u8,
    /// A whole epoch has been seen, so `sends` says what this receiver sends.
    learned: bool,
}

impl UbxEpoch {
    /// Takes one UBX frame the `ublox` crate read.
    pub fn push(&mut self, packet: &PacketRef<'_>) -> FrameOutcome {
        let (itow, part) = match packet {
            PacketRef::NavPvt(p) => (p.itow(), Part::Pvt(fix_from_nav_pvt(p))),
            PacketRef::HnrPvt(p) => (p.itow(), Part::Pvt(fix_from_hnr_pvt(p))),
            PacketRef::NavSol(p) => (p.itow(), Part::Sol(fix_from_nav_sol(p))),
            PacketRef::NavPosLlh(p) => match PosLlh::read(p) {
                Some(llh) => (p.itow(), Part::PosLlh(llh)),
                None => return FrameOutcome::Malformed,
            },
            PacketRef::NavVelNed(p) => match VelNed::read(p) {
                Some(v) => (p.itow(), Part::VelNed(v)),
                None => return FrameOutcome::Malformed,
            },
            PacketRef::NavDop(p) => (p.itow(), Part::Dop(hdop(p))),
            PacketRef::NavEoe(p) => (p.itow(), Part::EndOfEpoch),
            _ => return FrameOutcome::Unsupported,
        };
        if let Part::Pvt(fix) | Part::Sol(fix) = &part
            && !is_plausible(fix)
        {
            return FrameOutcome::Malformed;
        }
        let closed = match self.itow_ms {
            Some(current) if current == itow => None,
            Some(current) if is_late(current, itow) => return FrameOutcome::Late,
            _ => self.begin(itow),
        };
        let end_of_epoch = matches!(part, Part::EndOfEpoch);
        self.record(part);
        if end_of_epoch && self.have & POSITION != 0 {
            self.sends = self.have;
            self.learned = true;
        }
        let completed = if end_of_epoch || self.complete() {
            self.publish()
        } else {
            None
        };
        FrameOutcome::Used { closed, completed }
    }

    /// The fix of the epoch in progress if it has not been handed out: for the end of the
    /// receiver's output, when no later message will close it.
    pub fn flush(&mut self) -> Option<GnssFix> {
        self.publish()
    }

    /// Starts the epoch of `itow`; returns the fix of the one it closed, if not handed out yet.
    /// The closed epoch, if it had a position, shows what the receiver sends (the first one may
    /// have been joined halfway: the next whole epoch corrects that).
    fn begin(&mut self, itow: u32) -> Option<GnssFix> {
        let closed = self.publish();
        let whole = self.have & POSITION != 0;
        *self = Self {
            itow_ms: Some(itow),
            sends: if whole { self.have } else { self.sends },
            learned: self.learned || whole,
            ..Self::default()
        };
        closed
    }

    fn record(&mut self, part: Part) {
        let kind = match part {
            Part::Pvt(fix) => {
                self.pvt.get_or_insert(fix);
                PVT
            }
            Part::Sol(fix) => {
                self.sol = Some(fix);
                SOL
            }
            Part::PosLlh(p) => {
                self.pos_llh = Some(p);
                POSLLH
            }
            Part::VelNed(v) => {
                self.vel_ned = Some(v);
                VELNED
            }
            Part::Dop(h) => {
                self.hdop = Some(h);
                DOP
            }
            Part::EndOfEpoch => 0,
        };
        self.have |= kind;
    }

    /// Everything this receiver sends for an epoch is in.
    fn complete(&self) -> bool {
        self.have & PVT != 0
            || (self.learned && self.have & POSITION != 0 && self.have & self.sends == self.sends)
    }

    /// Hands out the epoch's fix, once, if it has a position.
    fn publish(&mut self) -> Option<GnssFix> {
        if self.published || self.have & POSITION == 0 {
            return None;
        }
        self.published = true;
        Some(self.fix())
    }

    /// The epoch's fix: NAV-PVT's (or HNR-PVT's) when there is one, else NAV-SOL's with
    /// NAV-POSLLH's position and NAV-VELNED's velocity; NAV-DOP's HDOP either way. Without a
    /// solution status (NAV-POSLLH alone) the position is not known to be a fix: no fix.
    fn fix(&self) -> GnssFix {
        let mut fix = if let Some(pvt) = self.pvt {
            pvt
        } else {
            let mut fix = self.sol.unwrap_or(GnssFix {
                version: PAYLOAD_VERSION,
                fix_type: GnssFixType::NoFix as u8,
                protocol: GnssProtocol::Ubx as u8,
                receiver_time_us: u64::from(self.itow_ms.unwrap_or(0)) * 1_000,
                ..GnssFix::default()
            });
            match self.pos_llh {
                Some(p) => p.apply(&mut fix),
                None => without_height(&mut fix),
            }
            if let Some(v) = self.vel_ned {
                v.apply(&mut fix);
            }
            fix
        };
        if let Some(h) = self.hdop {
            fix.hdop = h;
        }
        fix
    }
}

/// A NAV-SOL fix without NAV-POSLLH: its height is above the ellipsoid, and mean sea level is
/// not known without a geoid model, which the decoder does not carry. Rather than publish a height
/// that may be off by the geoid's ±100 m, the fix is horizontal only: a 3-D solution becomes 2-D
/// with no height (NaN, as an NMEA fix without altitude). A receiver configured to send NAV-PVT or
/// NAV-POSLLH gives 3-D fixes.
fn without_height(fix: &mut GnssFix) {
    if GnssFixType::from_u8(fix.fix_type).is_some_and(GnssFixType::is_3d) {
        fix.fix_type = GnssFixType::Fix2d as u8;
    }
    fix.altitude_m = f64::NAN;
    fix.vertical_accuracy_m = f64::NAN;
}

/// Whether `itow` lies up to [`LATE_WINDOW_MS`] before `current`, across the week's wrap.
fn is_late(current: u32, itow: u32) -> bool {
    let back = (i64::from(current) - i64::from(itow)).rem_euclid(WEEK_MS);
    back > 0 && back <= i64::from(LATE_WINDOW_MS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn late_is_a_short_step_back_even_across_the_week_wrap() {
        assert!(is_late(10_000, 9_000));
        assert!(is_late(10_000, 9_999));
        assert!(!is_late(10_000, 10_000));
        assert!(!is_late(10_000, 8_999));
        assert!(!is_late(10_000, 10_001));
        assert!(is_late(500, 604_799_600));
        assert!(!is_late(604_799_600, 500));
        assert!(!is_late(0, u32::MAX));
    }
}
