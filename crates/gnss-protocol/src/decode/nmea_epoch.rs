//! NMEA sentences of one receiver epoch put together into one fix.
//!
//! **Which sentences make an epoch.** Sentences whose UTC times differ by less than
//! [`SAME_EPOCH_US`] belong to one epoch (receivers round the same instant differently in
//! different sentences: `014421.076` in GLL, `014421.08` in GGA). VTG and GSA carry no time and
//! belong to the epoch in progress.
//!
//! **When it is published.** An epoch is handed out
//! - as soon as it holds every sentence (kind and talker) the two epochs before it held, so that
//!   a fix is not held back a whole period waiting for the next epoch's first sentence;
//! - otherwise when a sentence of another time arrives (a sentence was lost, or this is the first
//!   epoch and the decoder does not know yet what the receiver sends);
//! - otherwise when the receiver has sent nothing for it for [`EPOCH_QUIET_NS`], or at a flush
//!   (the end of a recording): the last epoch is not lost.
//!
//! Its receive time is that of its last timed sentence, whenever it is handed out (not of a VTG:
//! some receivers send the next epoch's VTG first, and the fix would be stamped a period late).
//!
//! **Which position.** A receiver may report one epoch from several talkers (GPGGA and GLGGA on
//! SiRF V, GPGGA and GNGNS on a BeiDou receiver). The fix is one of them, never simply the last:
//! - GGA/GNS reporting a satellite fix come first: the combined solution (talker GN) if there is
//!   one, else the one using the most satellites (the first of equals);
//! - RMC/GLL with a valid status are used only when no GGA/GNS of the epoch states a quality
//!   (receivers that send only RMC, or a GGA with an empty quality field): a two-dimensional fix,
//!   three-dimensional only when such a GGA/GNS of the epoch gives an altitude;
//! - a GGA/GNS without altitude gives a two-dimensional fix;
//! - the fix mode of the epoch's GSA (any talker; the best of several) overrides a satellite
//!   fix's: mode 2 makes it two-dimensional (the altitude the receiver gave is kept: it is the
//!   one it holds, not a measurement), mode 1 makes it no fix; without GSA a GGA/GNS fix with an
//!   altitude is three-dimensional. Dead reckoning is not a satellite fix and keeps its type;
//! - the receiver's dead reckoning (GGA quality 6, mode E) is published as such, and manual input
//!   or simulation (GGA 7, 8; mode M, S) as without a fix: neither is a satellite measurement.
//!
//! The satellite count is the combined solution's (GN) if the epoch has one, else the sum over
//! the talkers' GGA/GNS: each of those counts the satellites of its own system.
//!
//! **Accuracy.** GST's σ when the receiver sends it; else [`UERE_M`] × HDOP (vertical 1.5 times
//! that), and with no HDOP either, the HDOP of a poor geometry ([`HDOP_WHEN_UNREPORTED`]): a fix
//! of unknown accuracy must not look good. A two-dimensional fix has no vertical accuracy (NaN),
//! and no altitude unless a GSA made it two-dimensional.

use ipc_types::{GnssFix, GnssFixType, GnssProtocol, PAYLOAD_VERSION};

use super::nmea_reading::{self, FixMode, Position, Quality, Reading};
use super::nmea_sentence::{self, Kind, NmeaStats, Refused, Talker, Used};
use super::sanity::is_plausible;

/// Horizontal σ per unit of HDOP when the receiver sends no GST, m: the user-equivalent range
/// error of a single-frequency receiver.
pub const UERE_M: f64 = 3.0;

/// Vertical σ per horizontal σ without GST: the vertical geometry is about 1.5 times weaker.
const VERTICAL_PER_HORIZONTAL: f64 = 1.5;

/// Speed σ assumed when the receiver reports none (NMEA has no field for it), m/s.
pub const NMEA_SPEED_SIGMA_MPS: f64 = 0.2;

/// HDOP taken when the epoch reports none: the bound of a "fair" geometry in the usual rating of
/// dilution of precision (≤ 10 moderate, 10–20 fair), so that the fix counts as poor.
pub const HDOP_WHEN_UNREPORTED: f64 = 10.0;

/// Sentence times closer than this are one epoch, µs: receivers print one instant to 2 or 3
/// decimals, rounded or truncated (≤ 10 ms apart), while the fastest NMEA output rates (20 Hz)
/// are 50 ms apart.
pub const SAME_EPOCH_US: u64 = 10_000;

/// An epoch not yet complete is handed out once the receiver has sent nothing for it this long,
/// ns: longer than the gaps within one epoch's burst of sentences, shorter than a receiver at
/// 1 Hz leaves between epochs plus its burst.
pub const EPOCH_QUIET_NS: u64 = 1_000_000_000;

const DAY_US: u64 = 86_400_000_000;

/// What became of one sentence.
// Handed back by value and never stored: boxing the fixes would allocate per sentence.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SentenceOutcome {
    /// Used. `closed`: the fix of the epoch it closed (a sentence of a later time), if not
    /// handed out yet; `completed`: the fix of the epoch it completed.
    Used {
        /// The previous epoch, closed by this sentence's time.
        closed: Option<GnssFix>,
        /// This sentence's epoch, now complete.
        completed: Option<GnssFix>,
    },
    /// The checksum did not match.
    Checksum,
    /// No checksum to check.
    WithoutChecksum,
    /// Not readable as an NMEA sentence.
    Unparsable,
    /// Well-formed, but of a kind the decoder does not use or with nothing to use in it (counted
    /// by kind in [`NmeaStats`]).
    Unsupported,
    /// A used kind whose fields are out of format or range.
    Malformed,
}

/// One position sentence of the epoch in progress.
#[derive(Debug, Clone, Copy)]
struct Report {
    position: Position,
    kind: Used,
    /// Arrival order within the epoch.
    arrival: u8,
}

/// The epoch being assembled.
#[derive(Debug, Clone, Copy)]
struct Epoch {
    time_us: u64,
    last_rx_ns: u64,
    /// GGA or GNS (GGA kept over GNS), by talker.
    full: [Option<Report>; Talker::COUNT],
    /// RMC or GLL (RMC kept over GLL), by talker.
    planar: [Option<Report>; Talker::COUNT],
    vtg_velocity: Option<[f64; 2]>,
    /// The best fix mode of its GSA.
    fix_mode: Option<FixMode>,
    /// GST's horizontal and vertical σ.
    accuracy: Option<[f64; 2]>,
    /// The sentences it holds: one bit per kind and talker.
    seen: u64,
    arrivals: u8,
    /// Handed out: later sentences of its time are not a new epoch.
    published: bool,
}

/// Assembles the epochs of one receiver's NMEA output. Allocation-free.
#[derive(Debug, Clone, Copy, Default)]
pub struct NmeaEpoch {
    epoch: Option<Epoch>,
    /// The sentences of the last closed epoch and of the one before it.
    last: u64,
    before_last: u64,
    stats: NmeaStats,
}

impl NmeaEpoch {
    /// What it set aside so far.
    pub fn stats(&self) -> NmeaStats {
        self.stats
    }

    /// Takes one sentence as framed on the line (`$...*hh`, with or without `\r\n`), received at
    /// `rx_ns`.
    pub fn push(&mut self, raw: &[u8], rx_ns: u64) -> SentenceOutcome {
        let sentence = match nmea_sentence::read(raw) {
            Ok(s) => s,
            Err(Refused::Checksum) => return SentenceOutcome::Checksum,
            Err(Refused::WithoutChecksum) => {
                self.stats.without_checksum += 1;
                return SentenceOutcome::WithoutChecksum;
            }
            Err(Refused::Unreadable) => return SentenceOutcome::Unparsable,
        };
        let Kind::Used(kind) = sentence.kind else {
            self.stats.count(sentence.kind);
            return SentenceOutcome::Unsupported;
        };
        let Ok(reading) = nmea_reading::read(kind, sentence.fields) else {
            return SentenceOutcome::Malformed;
        };
        let bit = 1u64 << (kind as usize * Talker::COUNT + sentence.talker as usize);
        let closed = match reading {
            Reading::Position(p) => {
                let closed = self.begin(p.time_us, rx_ns);
                self.with_epoch(|e| e.add(kind, sentence.talker, p));
                closed
            }
            Reading::Accuracy {
                time_us,
                horizontal_m,
                vertical_m,
            } => {
                let closed = self.begin(time_us, rx_ns);
                self.with_epoch(|e| e.accuracy = Some([horizontal_m, vertical_m]));
                closed
            }
            Reading::Velocity(velocity) => {
                if self.epoch.is_none() {
                    self.stats.nothing_to_use += 1;
                    return SentenceOutcome::Unsupported;
                }
                // Its receive time is not the epoch's: a receiver that sends VTG before its
                // epoch's timed sentences would have its epochs stamped a period late.
                self.with_epoch(|e| {
                    if !e.published {
                        e.vtg_velocity = velocity.or(e.vtg_velocity);
                    }
                });
                None
            }
            Reading::FixMode(mode) => {
                let Some(epoch) = self.epoch.as_mut() else {
                    self.stats.gsa += 1;
                    return SentenceOutcome::Unsupported;
                };
                // A receiver sends one GSA per satellite system: the epoch's mode is the best.
                if !epoch.published {
                    epoch.fix_mode = epoch.fix_mode.max(Some(mode));
                }
                None
            }
            Reading::Nothing => {
                self.stats.nothing_to_use += 1;
                return SentenceOutcome::Unsupported;
            }
        };
        let expected = self.last | self.before_last;
        let complete = self.epoch.as_mut().is_some_and(|e| {
            // Recorded even after the epoch was handed out: the next epochs wait for it.
            e.seen |= bit;
            expected != 0 && e.seen & expected == expected && e.has_position()
        });
        let completed = if complete { self.hand_out() } else { None };
        SentenceOutcome::Used { closed, completed }
    }

    /// Hands out the epoch in progress if the receiver has sent nothing for it since a second
    /// (`EPOCH_QUIET_NS`) before `now_ns`.
    pub fn close_quiet(&mut self, now_ns: u64) -> Option<GnssFix> {
        let epoch = self.epoch.as_ref()?;
        if epoch.published || now_ns < epoch.last_rx_ns.saturating_add(EPOCH_QUIET_NS) {
            return None;
        }
        self.hand_out()
    }

    /// Hands out the epoch in progress, complete or not (at the end of the receiver's output).
    pub fn flush(&mut self) -> Option<GnssFix> {
        self.hand_out()
    }

    /// Makes the epoch in progress that of `time_us`: the same if of the same time, else a new
    /// one; returns the fix of the one it closed if that was not handed out yet.
    fn begin(&mut self, time_us: u64, rx_ns: u64) -> Option<GnssFix> {
        let same = self
            .epoch
            .as_ref()
            .is_some_and(|e| same_epoch(e.time_us, time_us));
        let mut closed = None;
        if !same {
            closed = self.hand_out();
            if let Some(old) = self.epoch.take() {
                (self.before_last, self.last) = (self.last, old.seen);
            }
        }
        let epoch = self.epoch.get_or_insert_with(|| Epoch::new(time_us, rx_ns));
        if !epoch.published {
            epoch.last_rx_ns = rx_ns;
        }
        closed
    }

    fn with_epoch(&mut self, change: impl FnOnce(&mut Epoch)) {
        if let Some(epoch) = self.epoch.as_mut() {
            change(epoch);
        }
    }

    /// The epoch in progress's fix, once: marks it handed out.
    fn hand_out(&mut self) -> Option<GnssFix> {
        let epoch = self.epoch.as_mut().filter(|e| !e.published)?;
        epoch.published = true;
        let rx_ns = epoch.last_rx_ns;
        let Some(fix) = epoch.fix() else {
            self.stats.epochs_without_position += 1;
            return None;
        };
        if GnssFixType::from_u8(fix.fix_type).is_some_and(GnssFixType::is_3d) && !is_plausible(&fix)
        {
            self.stats.implausible_epochs += 1;
            return Some(no_fix(fix.receiver_time_us, rx_ns));
        }
        Some(fix)
    }
}

/// Whether two times of day are one epoch (across midnight too).
fn same_epoch(a_us: u64, b_us: u64) -> bool {
    let d = a_us.abs_diff(b_us) % DAY_US;
    d.min(DAY_US - d) < SAME_EPOCH_US
}

impl Epoch {
    fn new(time_us: u64, rx_ns: u64) -> Self {
        Self {
            time_us,
            last_rx_ns: rx_ns,
            full: [None; Talker::COUNT],
            planar: [None; Talker::COUNT],
            vtg_velocity: None,
            fix_mode: None,
            accuracy: None,
            seen: 0,
            arrivals: 0,
            published: false,
        }
    }

    fn add(&mut self, kind: Used, talker: Talker, position: Position) {
        let (slot, preferred) = match kind {
            Used::Gga | Used::Gns => (&mut self.full[talker as usize], Used::Gga),
            _ => (&mut self.planar[talker as usize], Used::Rmc),
        };
        // A GGA is not replaced by the same talker's GNS, nor an RMC by its GLL.
        if slot.is_some_and(|r| r.kind == preferred && kind != preferred) {
            return;
        }
        *slot = Some(Report {
            position,
            kind,
            arrival: self.arrivals,
        });
        self.arrivals = self.arrivals.saturating_add(1);
    }

    fn has_position(&self) -> bool {
        self.full.iter().chain(&self.planar).any(Option::is_some)
    }

    /// The fix of the epoch, by the rules in the module's description; `None` without a
    /// position sentence.
    fn fix(&self) -> Option<GnssFix> {
        let full_fix = best(&self.full, |p| p.quality.is_fix());
        let stated = self
            .full
            .iter()
            .flatten()
            .any(|r| r.position.quality != Quality::Unknown);
        let planar_fix = best(&self.planar, |p| p.quality.is_fix()).filter(|_| !stated);
        let dead_reckoning = best(&self.full, |p| p.quality == Quality::DeadReckoning)
            .or_else(|| best(&self.planar, |p| p.quality == Quality::DeadReckoning));
        let any = best(&self.full, |_| true).or_else(|| best(&self.planar, |_| true))?;
        let chosen = full_fix.or(planar_fix).or(dead_reckoning).unwrap_or(any);
        let p = chosen.position;
        let mut fix = no_fix(p.time_us, self.last_rx_ns);
        fix.satellites = self.satellites();
        let fix_type = match (p.quality, self.fix_mode) {
            (Quality::Fix(_), Some(FixMode::NoFix)) => return Some(fix),
            (Quality::Fix(t), _) => t,
            (Quality::DeadReckoning, _) => GnssFixType::DeadReckoning,
            (Quality::NoFix | Quality::Unknown, _) => return Some(fix),
        };
        // A GGA/GNS that does not state its quality lends its altitude to the RMC/GLL.
        let altitude = p.altitude_m.or_else(|| {
            best(&self.full, |q| {
                q.quality == Quality::Unknown && q.altitude_m.is_some()
            })
            .and_then(|r| r.position.altitude_m)
        });
        let hdop = p
            .hdop
            .or_else(|| best(&self.full, |q| q.hdop.is_some()).and_then(|r| r.position.hdop));
        let two_d = self.fix_mode == Some(FixMode::TwoD);
        let fix_type = match (fix_type, altitude) {
            (GnssFixType::DeadReckoning, _) => GnssFixType::DeadReckoning,
            (_, Some(_)) if two_d => GnssFixType::Fix2d,
            (t, Some(_)) => t,
            (_, None) => GnssFixType::Fix2d,
        };
        fix.fix_type = fix_type as u8;
        fix.latitude_rad = p.latitude_deg.to_radians();
        fix.longitude_rad = p.longitude_deg.to_radians();
        fix.altitude_m = altitude.unwrap_or(f64::NAN);
        fix.hdop = hdop.unwrap_or(0.0);
        let [horizontal, vertical] = match self.accuracy {
            Some(sigma) => {
                fix.accuracy_reported = 1;
                sigma
            }
            None => {
                let h = hdop.unwrap_or(HDOP_WHEN_UNREPORTED) * UERE_M;
                [h, h * VERTICAL_PER_HORIZONTAL]
            }
        };
        fix.horizontal_accuracy_m = horizontal;
        fix.vertical_accuracy_m = if fix_type == GnssFixType::Fix2d || altitude.is_none() {
            f64::NAN
        } else {
            vertical
        };
        let rmc_velocity = best(&self.planar, |q| q.velocity_ne_mps.is_some())
            .and_then(|r| r.position.velocity_ne_mps);
        // RMC is timed, VTG is not: RMC's velocity is surely this epoch's.
        if let Some([north, east]) = rmc_velocity
            .or(self.vtg_velocity)
            .filter(|_| fix_type != GnssFixType::DeadReckoning)
        {
            fix.velocity_ned_mps = [north, east, 0.0];
            fix.velocity_valid = 1;
        }
        Some(fix)
    }

    /// The combined solution's count if there is one, else the sum of the systems' counts.
    fn satellites(&self) -> u8 {
        if let Some(gn) = self.full[Talker::Gn as usize] {
            return gn.position.satellites.unwrap_or(0);
        }
        let sum: u32 = self
            .full
            .iter()
            .flatten()
            .map(|r| u32::from(r.position.satellites.unwrap_or(0)))
            .sum();
        sum.min(255) as u8
    }
}

/// Of the reports that `wanted`: the combined solution's (GN), else the one using the most
/// satellites, the first of equals.
fn best(reports: &[Option<Report>], wanted: impl Fn(&Position) -> bool) -> Option<Report> {
    let candidates = reports.iter().flatten().filter(|r| wanted(&r.position));
    if let Some(gn) = reports[Talker::Gn as usize].filter(|r| wanted(&r.position)) {
        return Some(gn);
    }
    candidates.copied().min_by_key(|r| {
        (
            core::cmp::Reverse(r.position.satellites.unwrap_or(0)),
            r.arrival,
        )
    })
}

/// An epoch without a fix.
fn no_fix(time_us: u64, rx_ns: u64) -> GnssFix {
    let mut fix = GnssFix {
        version: PAYLOAD_VERSION,
        protocol: GnssProtocol::Nmea as u8,
        fix_type: GnssFixType::NoFix as u8,
        receiver_time_us: time_us,
        speed_accuracy_mps: NMEA_SPEED_SIGMA_MPS,
        ..GnssFix::default()
    };
    fix.header.origin_rx_ns = rx_ns;
    fix
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `$body*hh\r\n`.
    fn sentence(body: &str) -> Vec<u8> {
        let checksum = body.bytes().fold(0u8, |c, b| c ^ b);
        format!("${body}*{checksum:02X}\r\n").into_bytes()
    }

    fn gga(time: &str, altitude: &str) -> Vec<u8> {
        sentence(&format!(
            "GPGGA,{time},4807.038,N,01131.000,E,1,08,0.9,{altitude},M,46.9,M,,"
        ))
    }

    fn rmc(time: &str) -> Vec<u8> {
        sentence(&format!(
            "GPRMC,{time},A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W"
        ))
    }

    fn fixes(outcome: SentenceOutcome) -> (Option<GnssFix>, Option<GnssFix>) {
        match outcome {
            SentenceOutcome::Used { closed, completed } => (closed, completed),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_epoch_is_handed_out_once_it_holds_what_the_epochs_before_it_held() {
        let mut e = NmeaEpoch::default();
        assert_eq!(fixes(e.push(&gga("123519", "545.4"), 1)), (None, None));
        assert_eq!(fixes(e.push(&rmc("123519"), 2)), (None, None));
        // The first epoch: complete only when the next begins.
        let (closed, completed) = fixes(e.push(&gga("123520", "545.4"), 3));
        let closed = closed.unwrap();
        assert!(completed.is_none());
        assert_eq!(closed.header.origin_rx_ns, 2);
        assert_eq!(closed.fix_type, GnssFixType::Fix3d as u8);
        assert_eq!(closed.velocity_valid, 1);
        // The second: complete with its RMC, not a period later.
        let (closed, completed) = fixes(e.push(&rmc("123520"), 4));
        assert!(closed.is_none());
        assert_eq!(completed.unwrap().receiver_time_us, 45_320_000_000);
        // A late sentence of the same time is not a new epoch.
        assert_eq!(fixes(e.push(&rmc("123520.004"), 5)), (None, None));
        assert!(e.flush().is_none());
    }

    #[test]
    fn a_vtg_belongs_to_the_epoch_in_progress_but_not_its_receive_time() {
        let mut e = NmeaEpoch::default();
        e.push(&gga("123519", "545.4"), 10);
        e.push(&sentence("GPVTG,090.0,T,,M,10.0,N,18.5,K,A"), 20);
        let fix = e.flush().unwrap();
        assert_eq!(fix.header.origin_rx_ns, 10);
        assert_eq!(fix.velocity_valid, 1);
        assert!((fix.velocity_ned_mps[1] - 10.0 * 1852.0 / 3600.0).abs() < 1e-9);
        // No epoch to belong to.
        let mut e = NmeaEpoch::default();
        let vtg = sentence("GPVTG,090.0,T,,M,10.0,N,18.5,K,A");
        assert_eq!(e.push(&vtg, 1), SentenceOutcome::Unsupported);
        assert_eq!(e.stats().nothing_to_use, 1);
    }

    #[test]
    fn times_less_than_ten_milliseconds_apart_are_one_epoch_across_midnight_too() {
        assert!(same_epoch(45_319_076_000, 45_319_080_000));
        assert!(!same_epoch(45_319_000_000, 45_319_010_000));
        assert!(same_epoch(DAY_US - 5_000, 0));
        assert!(!same_epoch(DAY_US - 50_000, 0));
    }

    /// Garmin GPS 25LP (GPSD project regression logs): RMC, GGA with quality 1 and an altitude,
    /// then GSA.
    const GARMIN_RMC: &str =
        "$GPRMC,120327,A,4221.3872,N,01322.0800,E,000.0,000.0,150305,001.4,E*75\r\n";
    const GARMIN_GGA: &str =
        "$GPGGA,120327,4221.3872,N,01322.0800,E,1,03,3.1,746.1,M,44.2,M,,*41\r\n";
    const GSA_2D: &str = "$GPGSA,A,2,01,03,,14,,,,,,,,,3.1,3.1,*1A\r\n";
    /// A CH-4711 before its first fix.
    const GSA_NO_FIX: &str = "$GPGSA,A,1,,,,,,,,,,,,,00.0,00.0,00.0*00\r\n";
    /// A Garmin GPSmap 76S reporting a 3-D fix.
    const GSA_3D: &str = "$GPGSA,A,3,03,07,08,11,13,16,19,23,24,28,,,3.6,2.0,3.0*3A\r\n";

    fn epoch_with(gsa: &[&str]) -> (GnssFix, NmeaStats) {
        let mut e = NmeaEpoch::default();
        for (i, s) in [GARMIN_RMC, GARMIN_GGA].iter().chain(gsa).enumerate() {
            let outcome = e.push(s.as_bytes(), i as u64);
            assert!(matches!(outcome, SentenceOutcome::Used { .. }), "{s}");
        }
        (e.flush().unwrap(), e.stats())
    }

    #[test]
    fn a_gsa_of_the_epoch_states_its_fix_mode() {
        let (fix, _) = epoch_with(&[]);
        assert_eq!(fix.fix_type, GnssFixType::Fix3d as u8);
        // Mode 2: two-dimensional, with the altitude the receiver holds and no vertical σ.
        let (fix, _) = epoch_with(&[GSA_2D]);
        assert_eq!(fix.fix_type, GnssFixType::Fix2d as u8);
        assert_eq!(fix.altitude_m, 746.1);
        assert!(fix.vertical_accuracy_m.is_nan());
        assert!((fix.horizontal_accuracy_m - 3.1 * UERE_M).abs() < 1e-9);
        assert!((fix.latitude_rad.to_degrees() - (42.0 + 21.3872 / 60.0)).abs() < 1e-12);
        // Mode 1: no fix, whatever the GGA's quality.
        let (fix, _) = epoch_with(&[GSA_NO_FIX]);
        assert_eq!(fix.fix_type, GnssFixType::NoFix as u8);
        assert!(fix.latitude_rad == 0.0 && fix.satellites == 3);
        // Several GSA (one per satellite system): the best mode.
        let (fix, _) = epoch_with(&[GSA_NO_FIX, GSA_2D]);
        assert_eq!(fix.fix_type, GnssFixType::Fix2d as u8);
        let (fix, _) = epoch_with(&[GSA_2D, GSA_3D, GSA_NO_FIX]);
        assert_eq!(fix.fix_type, GnssFixType::Fix3d as u8);
        assert!((fix.vertical_accuracy_m - 3.1 * UERE_M * VERTICAL_PER_HORIZONTAL).abs() < 1e-9);
    }

    #[test]
    fn a_gsa_with_no_epoch_in_progress_is_counted_and_not_used() {
        let mut e = NmeaEpoch::default();
        assert_eq!(e.push(GSA_2D.as_bytes(), 1), SentenceOutcome::Unsupported);
        assert_eq!(e.stats().gsa, 1);
        // It does not carry over to the next epoch.
        e.push(GARMIN_GGA.as_bytes(), 2);
        assert_eq!(e.flush().unwrap().fix_type, GnssFixType::Fix3d as u8);
    }

    #[test]
    fn a_gsa_after_its_epoch_was_handed_out_changes_nothing() {
        let mut e = NmeaEpoch::default();
        e.push(GARMIN_GGA.as_bytes(), 1);
        let fix = e.flush().unwrap();
        assert_eq!(fix.fix_type, GnssFixType::Fix3d as u8);
        assert_eq!(fixes(e.push(GSA_NO_FIX.as_bytes(), 2)), (None, None));
        assert!(e.flush().is_none());
    }

    #[test]
    fn an_implausible_fix_is_published_as_none_and_counted() {
        let mut e = NmeaEpoch::default();
        e.push(&gga("123519", "60000.0"), 1);
        let fix = e.flush().unwrap();
        assert_eq!(fix.fix_type, GnssFixType::NoFix as u8);
        assert_eq!(e.stats().implausible_epochs, 1);
    }

    #[test]
    fn an_epoch_of_only_accuracy_is_not_published_and_is_counted() {
        let mut e = NmeaEpoch::default();
        e.push(&sentence("GPGST,123519.00,1.8,,,,1.7,1.3,2.2"), 1);
        let (closed, _) = fixes(e.push(&gga("123520", "545.4"), 2));
        assert!(closed.is_none());
        assert_eq!(e.stats().epochs_without_position, 1);
        assert!(e.flush().is_some());
    }
}
