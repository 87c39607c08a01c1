//! NMEA sentences of one receiver epoch (GGA position, RMC or VTG velocity, GST accuracy) put
//! together into one fix.
//!
//! Sentences of the same UTC time belong to one epoch; VTG carries no time and belongs to the
//! epoch in progress. An epoch is complete as soon as its GGA and RMC are in, and its GST and VTG
//! when the receiver has been seen to send them — so that a fix is not held back a whole period
//! waiting for the next epoch's first sentence. An epoch left incomplete (a sentence lost) is
//! published when a sentence of another time arrives; so is the very first epoch, before the
//! decoder knows which sentences this receiver sends.

use chrono::Timelike;
use ipc_types::{GnssFix, GnssFixType, GnssProtocol, PAYLOAD_VERSION};
use nmea::sentences::FixType;
use nmea::{Error, ParseResult};

use super::sanity::is_plausible;

/// Metres per knot-second: 1852 m / 3600 s.
const KNOT_MPS: f64 = 1852.0 / 3600.0;

/// Horizontal σ per unit of HDOP when the receiver sends no GST, m: the user-equivalent range
/// error of a single-frequency receiver.
pub const UERE_M: f64 = 3.0;

/// Vertical σ per horizontal σ without GST: the vertical geometry is about 1.5 times weaker.
const VERTICAL_PER_HORIZONTAL: f64 = 1.5;

/// Speed σ assumed when the receiver reports none (NMEA has no field for it), m/s.
pub const NMEA_SPEED_SIGMA_MPS: f64 = 0.2;

/// What became of one sentence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SentenceOutcome {
    /// Used; with the fix of an epoch it completed (or of the one it closed).
    Used(Option<GnssFix>),
    /// The checksum did not match.
    Checksum,
    /// Not readable as NMEA.
    Unparsable,
    /// A sentence of another kind.
    Unsupported,
    /// Values out of range.
    Malformed,
}

/// The epoch being assembled.
#[derive(Debug, Clone, Copy, Default)]
pub struct NmeaEpoch {
    time_us: Option<u64>,
    fix: Option<GnssFix>,
    has_gga: bool,
    has_rmc: bool,
    has_gst: bool,
    has_vtg: bool,
    /// Already handed out: later sentences of the same time are not a new epoch.
    published: bool,
    sends_gst: bool,
    sends_vtg: bool,
    /// A whole epoch has been seen, so `sends_*` say what this receiver sends: until then an
    /// epoch is complete only when the next one starts.
    learned: bool,
}

impl NmeaEpoch {
    /// Takes one sentence as framed on the line (`$...*hh`, with or without `\r\n`).
    pub fn push(&mut self, raw: &[u8]) -> SentenceOutcome {
        let trimmed = trim_line_end(raw);
        let parsed = match nmea::parse_bytes(trimmed) {
            Ok(parsed) => parsed,
            Err(Error::ChecksumMismatch { .. }) => return SentenceOutcome::Checksum,
            Err(Error::Unsupported(_) | Error::Unknown(_)) => {
                return SentenceOutcome::Unsupported;
            }
            Err(_) => return SentenceOutcome::Unparsable,
        };
        match parsed {
            ParseResult::GGA(gga) => {
                let Some(time_us) = gga.fix_time.map(time_of_day_us) else {
                    return SentenceOutcome::Malformed;
                };
                let closed = self.begin(time_us);
                let fix = self.fix_mut();
                fix.fix_type = gga.fix_type.map_or(GnssFixType::NoFix, fix_type) as u8;
                fix.satellites = gga.fix_satellites.map_or(0, |n| n.min(255) as u8);
                fix.latitude_rad = gga.latitude.unwrap_or(f64::NAN).to_radians();
                fix.longitude_rad = gga.longitude.unwrap_or(f64::NAN).to_radians();
                fix.altitude_m = gga.altitude.map_or(f64::NAN, f64::from);
                fix.hdop = gga.hdop.map_or(0.0, f64::from);
                if fix.accuracy_reported == 0 {
                    let sigma = fix.hdop * UERE_M;
                    fix.horizontal_accuracy_m = sigma;
                    fix.vertical_accuracy_m = sigma * VERTICAL_PER_HORIZONTAL;
                }
                if GnssFixType::from_u8(fix.fix_type).is_some_and(GnssFixType::is_3d)
                    && !is_plausible(fix)
                {
                    *fix = GnssFix {
                        receiver_time_us: time_us,
                        ..GnssFix::default()
                    };
                    return SentenceOutcome::Malformed;
                }
                self.has_gga = true;
                self.finish(closed)
            }
            ParseResult::RMC(rmc) => {
                let Some(time_us) = rmc.fix_time.map(time_of_day_us) else {
                    return SentenceOutcome::Malformed;
                };
                let closed = self.begin(time_us);
                if let (Some(speed), Some(course)) = (rmc.speed_over_ground, rmc.true_course) {
                    self.set_velocity(f64::from(speed), f64::from(course));
                }
                self.has_rmc = true;
                self.finish(closed)
            }
            ParseResult::GST(gst) => {
                let Some(time_us) = gst.time.map(time_of_day_us) else {
                    return SentenceOutcome::Malformed;
                };
                let closed = self.begin(time_us);
                self.sends_gst = true;
                if let (Some(lat), Some(lon), Some(alt)) = (gst.lat_sd, gst.long_sd, gst.alt_sd) {
                    let (lat, lon) = (f64::from(lat), f64::from(lon));
                    let fix = self.fix_mut();
                    fix.horizontal_accuracy_m = ((lat * lat + lon * lon) / 2.0).sqrt();
                    fix.vertical_accuracy_m = f64::from(alt);
                    fix.accuracy_reported = 1;
                }
                self.has_gst = true;
                self.finish(closed)
            }
            ParseResult::VTG(vtg) => {
                self.sends_vtg = true;
                if self.time_us.is_none() || self.published {
                    // No epoch in progress to belong to.
                    return SentenceOutcome::Used(None);
                }
                if let (Some(speed), Some(course)) = (vtg.speed_over_ground, vtg.true_course) {
                    self.set_velocity(f64::from(speed), f64::from(course));
                }
                self.has_vtg = true;
                self.finish(None)
            }
            _ => SentenceOutcome::Unsupported,
        }
    }

    /// Starts the epoch of `time_us` unless it is the one in progress; returns the fix of the
    /// epoch it closed, if that one had a position and was not handed out yet.
    fn begin(&mut self, time_us: u64) -> Option<GnssFix> {
        if self.time_us == Some(time_us) {
            return None;
        }
        let closed = self.fix.filter(|_| self.has_gga && !self.published);
        *self = Self {
            time_us: Some(time_us),
            fix: Some(GnssFix {
                version: PAYLOAD_VERSION,
                protocol: GnssProtocol::Nmea as u8,
                receiver_time_us: time_us,
                speed_accuracy_mps: NMEA_SPEED_SIGMA_MPS,
                ..GnssFix::default()
            }),
            sends_gst: self.sends_gst,
            sends_vtg: self.sends_vtg,
            learned: self.time_us.is_some(),
            ..Self::default()
        };
        closed
    }

    fn fix_mut(&mut self) -> &mut GnssFix {
        self.fix.get_or_insert_with(GnssFix::default)
    }

    /// Ground speed (knots) and true course (degrees) as a NED velocity.
    fn set_velocity(&mut self, knots: f64, course_deg: f64) {
        let speed = knots * KNOT_MPS;
        let course = course_deg.to_radians();
        let fix = self.fix_mut();
        fix.velocity_ned_mps = [speed * course.cos(), speed * course.sin(), 0.0];
        fix.velocity_valid = 1;
    }

    /// The sentence was used: `closed` is the epoch it closed; the epoch in progress is handed
    /// out too once it has everything this receiver sends.
    fn finish(&mut self, closed: Option<GnssFix>) -> SentenceOutcome {
        let complete = self.learned
            && self.has_gga
            && self.has_rmc
            && (self.has_gst || !self.sends_gst)
            && (self.has_vtg || !self.sends_vtg);
        if closed.is_none() && complete && !self.published {
            self.published = true;
            return SentenceOutcome::Used(self.fix);
        }
        SentenceOutcome::Used(closed)
    }
}

/// The sentence without its line end.
fn trim_line_end(raw: &[u8]) -> &[u8] {
    let mut end = raw.len();
    while end > 0 && matches!(raw[end - 1], b'\r' | b'\n') {
        end -= 1;
    }
    &raw[..end]
}

fn time_of_day_us(t: chrono::NaiveTime) -> u64 {
    u64::from(t.num_seconds_from_midnight()) * 1_000_000 + u64::from(t.nanosecond() / 1_000)
}

/// GGA's quality indicator as a fix type.
fn fix_type(t: FixType) -> GnssFixType {
    match t {
        FixType::Gps | FixType::Pps => GnssFixType::Fix3d,
        FixType::DGps => GnssFixType::Differential,
        FixType::Rtk => GnssFixType::RtkFixed,
        FixType::FloatRtk => GnssFixType::RtkFloat,
        FixType::Estimated => GnssFixType::DeadReckoning,
        FixType::Invalid | FixType::Manual | FixType::Simulation => GnssFixType::NoFix,
    }
}
