//! What each sentence the decoder uses says, read field by field from NMEA 0183 (4.11 layouts,
//! with the older ones that omit the trailing mode fields).
//!
//! The `nmea` crate refuses much of what real receivers send: a GGA whose quality field is empty,
//! an RMC with status V and empty fields, a GNS with a mode letter per satellite system, a GLL
//! without the mode field; and it ignores VTG's mode letter (N: not valid). These readers take
//! every layout the standard allows and refuse only fields out of format or range.

use ipc_types::GnssFixType;

use super::nmea_fields::{BadField, Field, Fields};
use super::nmea_sentence::Used;

/// Metres per second per knot: 1852 m / 3600 s.
const KNOT_MPS: f64 = 1852.0 / 3600.0;

/// How good a position the sentence reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quality {
    /// No position, or one not for navigation (manual input, simulation, a GNS or RMC that says
    /// not valid).
    NoFix,
    /// The receiver's own dead reckoning.
    DeadReckoning,
    /// A satellite fix of this type (autonomous, differential, RTK): three-dimensional when the
    /// epoch has an altitude.
    Fix(GnssFixType),
    /// A GGA whose quality field is empty: the receiver does not say.
    Unknown,
}

impl Quality {
    /// A satellite fix.
    pub fn is_fix(self) -> bool {
        matches!(self, Self::Fix(_))
    }

    /// Its rank when a report of each kind is at hand: the better fix.
    fn rank(self) -> u8 {
        match self {
            Self::Unknown | Self::NoFix => 0,
            Self::DeadReckoning => 1,
            Self::Fix(GnssFixType::Fix3d) => 2,
            Self::Fix(GnssFixType::Differential) => 3,
            Self::Fix(GnssFixType::RtkFloat) => 4,
            Self::Fix(_) => 5,
        }
    }
}

/// The fix mode a GSA states, worst first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum FixMode {
    /// 1: no fix.
    NoFix,
    /// 2: two-dimensional (the altitude held, not measured).
    TwoD,
    /// 3: three-dimensional.
    ThreeD,
}

/// A position sentence (GGA, GNS, RMC, GLL).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Position {
    /// UTC time of day, µs.
    pub time_us: u64,
    /// What the receiver says of it.
    pub quality: Quality,
    /// Latitude, degrees (NaN when not given).
    pub latitude_deg: f64,
    /// Longitude, degrees (NaN when not given).
    pub longitude_deg: f64,
    /// Altitude above mean sea level, m (GGA, GNS).
    pub altitude_m: Option<f64>,
    /// Satellites used (GGA, GNS).
    pub satellites: Option<u8>,
    /// Horizontal dilution of precision (GGA, GNS).
    pub hdop: Option<f64>,
    /// Ground velocity north and east, m/s (RMC with a valid status, speed and course).
    pub velocity_ne_mps: Option<[f64; 2]>,
}

/// What one used sentence says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reading {
    /// A position report.
    Position(Position),
    /// GST: position σ north, east (combined as one horizontal σ per axis) and down.
    Accuracy {
        /// UTC time of day, µs.
        time_us: u64,
        /// Horizontal σ per axis, m.
        horizontal_m: f64,
        /// Vertical σ, m.
        vertical_m: f64,
    },
    /// VTG: ground velocity north and east, m/s, when it gives one; it has no time.
    Velocity(Option<[f64; 2]>),
    /// GSA: the fix mode of the solution; it has no time.
    FixMode(FixMode),
    /// A timed sentence without its time, a GST without σ, a GSA without its mode: nothing to
    /// place or use.
    Nothing,
}

/// Reads the fields of a sentence of kind `kind`.
pub fn read(kind: Used, mut f: Fields<'_>) -> Result<Reading, BadField> {
    match kind {
        Used::Gga => gga(&mut f),
        Used::Gns => gns(&mut f),
        Used::Rmc => rmc(&mut f),
        Used::Gll => gll(&mut f),
        Used::Gst => gst(&mut f),
        Used::Vtg => vtg(&mut f),
        Used::Gsa => gsa(&mut f),
    }
}

/// `time,lat,N,lon,E,quality,satellites,hdop,altitude,M,geoid,M,age,station`.
fn gga(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    let time = f.time_of_day_us()?;
    let (lat, lon) = (f.latitude_deg(), f.longitude_deg());
    let quality = match f.flag(b"012345678")? {
        None => Quality::Unknown,
        Some(b'0' | b'7' | b'8') => Quality::NoFix,
        Some(b'1' | b'3') => Quality::Fix(GnssFixType::Fix3d),
        Some(b'2') => Quality::Fix(GnssFixType::Differential),
        Some(b'4') => Quality::Fix(GnssFixType::RtkFixed),
        Some(b'5') => Quality::Fix(GnssFixType::RtkFloat),
        Some(_) => Quality::DeadReckoning,
    };
    let (satellites, hdop, altitude_m) = (f.count()?, f.unsigned()?, f.signed()?);
    position(time, quality, lat, lon, altitude_m, satellites, hdop, None)
}

/// `time,lat,N,lon,E,modes,satellites,hdop,altitude,geoid,age,station[,status]`: one mode letter
/// per satellite system (GPS, GLONASS, Galileo, BeiDou, …); the best of them is the fix's.
fn gns(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    let time = f.time_of_day_us()?;
    let (lat, lon) = (f.latitude_deg(), f.longitude_deg());
    let modes = f.text();
    if modes.is_empty() || modes.len() > 8 {
        return Err(BadField);
    }
    let mut quality = Quality::NoFix;
    for m in modes.bytes() {
        let q = mode(Some(m))?;
        if q.rank() > quality.rank() {
            quality = q;
        }
    }
    let (satellites, hdop, altitude_m) = (f.count()?, f.unsigned()?, f.signed()?);
    f.skip(3);
    // NMEA 4.10 navigational status: V, not valid for navigation.
    if f.flag(b"SCUV")? == Some(b'V') {
        quality = Quality::NoFix;
    }
    position(time, quality, lat, lon, altitude_m, satellites, hdop, None)
}

/// `time,status,lat,N,lon,E,speed,course,date,variation,E/W[,mode[,status]]`.
fn rmc(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    let time = f.time_of_day_us()?;
    let valid = f.flag(b"AV")? == Some(b'A');
    let (lat, lon) = (f.latitude_deg(), f.longitude_deg());
    let (speed_kn, course) = (f.unsigned()?, f.unsigned()?);
    f.skip(3);
    let quality = if valid {
        mode(f.flag(b"ADEFMNPRS")?)?
    } else {
        Quality::NoFix
    };
    let velocity = match (speed_kn, course) {
        (Some(speed), Some(course)) if quality.is_fix() => Some(ground_velocity(speed, course)?),
        _ => None,
    };
    position(time, quality, lat, lon, None, None, None, velocity)
}

/// `lat,N,lon,E,time,status[,mode]`.
fn gll(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    let (lat, lon) = (f.latitude_deg(), f.longitude_deg());
    let time = f.time_of_day_us()?;
    let valid = f.flag(b"AV")? == Some(b'A');
    let quality = if valid {
        mode(f.flag(b"ADEFMNPRS")?)?
    } else {
        Quality::NoFix
    };
    position(time, quality, lat, lon, None, None, None, None)
}

/// `time,rms,major,minor,orientation,lat σ,lon σ,alt σ`.
fn gst(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    let time = f.time_of_day_us()?;
    f.skip(4);
    let (lat, lon, alt) = (f.unsigned()?, f.unsigned()?, f.unsigned()?);
    Ok(match (time, lat, lon, alt) {
        (Some(time_us), Some(lat), Some(lon), Some(alt)) => Reading::Accuracy {
            time_us,
            horizontal_m: ((lat * lat + lon * lon) / 2.0).sqrt(),
            vertical_m: alt,
        },
        _ => Reading::Nothing,
    })
}

/// `course,T,course,M,speed,N,speed,K[,mode]`.
fn vtg(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    let course = f.unsigned()?;
    f.unit(b'T')?;
    f.skip(2);
    let knots = f.unsigned()?;
    f.unit(b'N')?;
    let kmh = f.unsigned()?;
    f.unit(b'K')?;
    let quality = mode(f.flag(b"ADEFMNPRS")?)?;
    let speed_kn = knots.or(kmh.map(|k| k / 1.852));
    Ok(Reading::Velocity(match (speed_kn, course) {
        (Some(speed), Some(course)) if quality.is_fix() => Some(ground_velocity(speed, course)?),
        _ => None,
    }))
}

/// `selection,mode,satellite×12,PDOP,HDOP,VDOP[,system]`: selection M (manual) or A (automatic),
/// mode 1 (no fix), 2 (2-D) or 3 (3-D).
fn gsa(f: &mut Fields<'_>) -> Result<Reading, BadField> {
    f.flag(b"MA")?;
    Ok(match f.flag(b"123")? {
        None => Reading::Nothing,
        Some(b'1') => Reading::FixMode(FixMode::NoFix),
        Some(b'2') => Reading::FixMode(FixMode::TwoD),
        Some(_) => Reading::FixMode(FixMode::ThreeD),
    })
}

/// The NMEA 2.3+ mode letter (absent in older sentences: the status alone says valid).
fn mode(letter: Option<u8>) -> Result<Quality, BadField> {
    Ok(match letter {
        None | Some(b'A' | b'P') => Quality::Fix(GnssFixType::Fix3d),
        Some(b'D') => Quality::Fix(GnssFixType::Differential),
        Some(b'F') => Quality::Fix(GnssFixType::RtkFloat),
        Some(b'R') => Quality::Fix(GnssFixType::RtkFixed),
        Some(b'E') => Quality::DeadReckoning,
        Some(b'N' | b'M' | b'S') => Quality::NoFix,
        Some(_) => return Err(BadField),
    })
}

/// Ground speed (knots) and true course (degrees) as north and east, m/s.
fn ground_velocity(speed_kn: f64, course_deg: f64) -> Result<[f64; 2], BadField> {
    if course_deg > 360.0 {
        return Err(BadField);
    }
    let (speed, course) = (speed_kn * KNOT_MPS, course_deg.to_radians());
    Ok([speed * course.cos(), speed * course.sin()])
}

/// A position report, or nothing without a time. A fix needs a latitude and a longitude; a
/// sentence that says it has none may carry anything there (MediaTek chips write `8960.000000,N`
/// until their first fix), and the fields are not read.
#[allow(clippy::too_many_arguments)]
fn position(
    time: Option<u64>,
    quality: Quality,
    latitude: Field<f64>,
    longitude: Field<f64>,
    altitude_m: Option<f64>,
    satellites: Option<u8>,
    hdop: Option<f64>,
    velocity_ne_mps: Option<[f64; 2]>,
) -> Result<Reading, BadField> {
    let positioned = matches!(quality, Quality::Fix(_) | Quality::DeadReckoning);
    let (latitude, longitude) = match (latitude, longitude) {
        (Ok(Some(lat)), Ok(Some(lon))) => (Some(lat), Some(lon)),
        _ if positioned => return Err(BadField),
        (lat, lon) => (lat.ok().flatten(), lon.ok().flatten()),
    };
    let Some(time_us) = time else {
        return Ok(Reading::Nothing);
    };
    Ok(Reading::Position(Position {
        time_us,
        quality,
        latitude_deg: latitude.unwrap_or(f64::NAN),
        longitude_deg: longitude.unwrap_or(f64::NAN),
        altitude_m,
        satellites,
        hdop,
        velocity_ne_mps,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reading(kind: Used, fields: &str) -> Result<Reading, BadField> {
        read(kind, Fields::new(fields))
    }

    fn position_of(kind: Used, fields: &str) -> Position {
        match reading(kind, fields) {
            Ok(Reading::Position(p)) => p,
            other => panic!("{fields}: {other:?}"),
        }
    }

    #[test]
    fn gga_quality_says_what_the_position_is() {
        let with = |q: &str| {
            position_of(
                Used::Gga,
                &format!("123519,4807.038,N,01131.000,E,{q},08,0.9,545.4,M,46.9,M,,"),
            )
            .quality
        };
        assert_eq!(with("1"), Quality::Fix(GnssFixType::Fix3d));
        assert_eq!(with("2"), Quality::Fix(GnssFixType::Differential));
        assert_eq!(with("4"), Quality::Fix(GnssFixType::RtkFixed));
        assert_eq!(with("5"), Quality::Fix(GnssFixType::RtkFloat));
        assert_eq!(with("6"), Quality::DeadReckoning);
        assert_eq!(with("7"), Quality::NoFix);
        assert_eq!(with("8"), Quality::NoFix);
        assert_eq!(with(""), Quality::Unknown);
        assert_eq!(
            reading(
                Used::Gga,
                "123519,4807.038,N,01131.000,E,9,08,0.9,545.4,M,46.9,M,,"
            ),
            Err(BadField)
        );
    }

    #[test]
    fn a_gga_without_altitude_or_hdop_leaves_them_out() {
        // Septentrio PolaRx2 and Saab R4 (GPSD project regression logs).
        let p = position_of(
            Used::Gga,
            "112301.00,3844.23907,N,00908.43804,W,1,03,10.5,,,,,,",
        );
        assert_eq!(
            (p.altitude_m, p.satellites, p.hdop),
            (None, Some(3), Some(10.5))
        );
        let p = position_of(Used::Gga, "130722,5012.792600,N,00806.879600,W,2,,,,,,,");
        assert_eq!((p.altitude_m, p.satellites, p.hdop), (None, None, None));
        assert_eq!(p.quality, Quality::Fix(GnssFixType::Differential));
    }

    #[test]
    fn a_fix_without_a_position_is_malformed_and_no_fix_needs_none() {
        assert_eq!(
            reading(Used::Gga, "123519,,,,,1,08,0.9,545.4,M,,M,,"),
            Err(BadField)
        );
        let p = position_of(Used::Gga, "053229.438,,,,,0,00,,,M,0.0,M,,0000");
        assert_eq!(p.quality, Quality::NoFix);
        assert!(p.latitude_deg.is_nan());
        let p = position_of(Used::Rmc, "212607.891,V,,,,,,,181207,0,N");
        assert_eq!(p.quality, Quality::NoFix);
        assert_eq!(reading(Used::Rmc, ",V,,,,,,,,,,N"), Ok(Reading::Nothing));
        // MediaTek before its first fix (GPSD project regression logs, mtk-3301).
        let p = position_of(
            Used::Gga,
            "235946.005,8960.000000,N,00000.000000,E,0,0,,137.000,M,13.000,M,,",
        );
        assert_eq!(p.quality, Quality::NoFix);
        assert!(p.latitude_deg.is_nan());
        assert_eq!(
            reading(
                Used::Gga,
                "235946.005,8960.000000,N,00000.000000,E,1,5,1.0,137.000,M,,M,,"
            ),
            Err(BadField)
        );
    }

    #[test]
    fn gns_takes_the_best_mode_of_its_systems() {
        // BeiDou receiver (GPSD project regression logs).
        let p = position_of(
            Used::Gns,
            "074156.799,3114.8950,N,12135.2442,E,ANNA,07,1.1,190.7,8.3,,0000",
        );
        assert_eq!(p.quality, Quality::Fix(GnssFixType::Fix3d));
        assert_eq!((p.satellites, p.altitude_m), (Some(7), Some(190.7)));
        let p = position_of(Used::Gns, "074150.799,,,,,NNNN,00,,,0.0,,0000");
        assert_eq!(p.quality, Quality::NoFix);
        let p = position_of(
            Used::Gns,
            "224749.00,3333.4268304,N,11153.3538273,W,DR,19,0.6,406.110,-26.294,6.0,0138,S",
        );
        assert_eq!(p.quality, Quality::Fix(GnssFixType::RtkFixed));
        let p = position_of(
            Used::Gns,
            "224749.00,3333.4268304,N,11153.3538273,W,DR,19,0.6,406.110,-26.294,6.0,0138,V",
        );
        assert_eq!(p.quality, Quality::NoFix);
        assert_eq!(
            reading(Used::Gns, "074156.799,,,,,AX,07,,,,,"),
            Err(BadField)
        );
    }

    #[test]
    fn rmc_and_gll_with_and_without_the_mode_letter() {
        let p = position_of(
            Used::Rmc,
            "123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W",
        );
        assert_eq!(p.quality, Quality::Fix(GnssFixType::Fix3d));
        let v = p.velocity_ne_mps.unwrap();
        let speed = 22.4 * KNOT_MPS;
        assert!((v[0] - speed * 84.4f64.to_radians().cos()).abs() < 1e-9);
        assert!((v[1] - speed * 84.4f64.to_radians().sin()).abs() < 1e-9);
        let p = position_of(
            Used::Rmc,
            "130711.00,A,5012.790800,N,00806.879600,W,0.5,3.0,010611,,,E",
        );
        assert_eq!(
            (p.quality, p.velocity_ne_mps),
            (Quality::DeadReckoning, None)
        );
        // Garmin in simulator mode: status V, mode S.
        let p = position_of(
            Used::Rmc,
            "125106,V,3854.5087,N,07726.4523,W,0.0,0.0,241011,10.5,W,S",
        );
        assert_eq!(p.quality, Quality::NoFix);
        let p = position_of(Used::Gll, "4426.1130,N,07140.5579,W,194102,A");
        assert_eq!(p.quality, Quality::Fix(GnssFixType::Fix3d));
        assert_eq!(p.time_us, (19 * 3600 + 41 * 60 + 2) * 1_000_000);
        let p = position_of(Used::Gll, "3728.0549,N,12213.8639,W,014413.076,V,N");
        assert_eq!(p.quality, Quality::NoFix);
        // Magellan eXplorist 110 swaps status and mode: not NMEA, malformed.
        assert_eq!(
            reading(Used::Gll, "3728.0549,N,12213.8639,W,014413.076,N,V"),
            Err(BadField)
        );
        let p = position_of(Used::Gll, "4552.65550,S,17030.00756,E,011903.00,A,A");
        assert!((p.latitude_deg + (45.0 + 52.6555 / 60.0)).abs() < 1e-12);
    }

    #[test]
    fn gst_and_vtg() {
        assert_eq!(
            reading(Used::Gst, "082356.00,1.8,,,,1.7,1.3,2.2"),
            Ok(Reading::Accuracy {
                time_us: (8 * 3600 + 23 * 60 + 56) * 1_000_000,
                horizontal_m: ((1.7f64 * 1.7 + 1.3 * 1.3) / 2.0).sqrt(),
                vertical_m: 2.2,
            })
        );
        assert_eq!(
            reading(Used::Gst, "082356.00,1.8,,,,,,"),
            Ok(Reading::Nothing)
        );
        let Ok(Reading::Velocity(Some(v))) = reading(Used::Vtg, "090.0,T,,M,10.0,N,18.5,K,A")
        else {
            panic!()
        };
        assert!(v[0].abs() < 1e-9 && (v[1] - 10.0 * KNOT_MPS).abs() < 1e-9);
        assert_eq!(
            reading(Used::Vtg, "090.0,T,,M,10.0,N,18.5,K,N"),
            Ok(Reading::Velocity(None))
        );
        assert_eq!(
            reading(Used::Vtg, ",T,,M,0.214,N,0.396,K,A"),
            Ok(Reading::Velocity(None))
        );
        assert_eq!(
            reading(Used::Vtg, "090.0,X,,M,10.0,N,18.5,K"),
            Err(BadField)
        );
    }

    #[test]
    fn gsa_states_the_fix_mode() {
        // Garmin GPS 25LP, CH-4711, Garmin GPSmap 76S (GPSD project regression logs).
        assert_eq!(
            reading(Used::Gsa, "A,2,01,03,,14,,,,,,,,,3.1,3.1,"),
            Ok(Reading::FixMode(FixMode::TwoD))
        );
        assert_eq!(
            reading(Used::Gsa, "A,1,,,,,,,,,,,,,00.0,00.0,00.0"),
            Ok(Reading::FixMode(FixMode::NoFix))
        );
        assert_eq!(
            reading(Used::Gsa, "A,3,03,07,08,11,13,16,19,23,24,28,,,3.6,2.0,3.0"),
            Ok(Reading::FixMode(FixMode::ThreeD))
        );
        assert_eq!(
            reading(Used::Gsa, "A,,,,,,,,,,,,,,,,"),
            Ok(Reading::Nothing)
        );
        assert_eq!(reading(Used::Gsa, "A,4,,,,,,,,,,,,,,,"), Err(BadField));
        assert!(FixMode::ThreeD > FixMode::TwoD && FixMode::TwoD > FixMode::NoFix);
    }
}
