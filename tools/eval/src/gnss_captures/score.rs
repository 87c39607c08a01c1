//! Published fixes against the reference epochs: matched by the receiver's time, compared by
//! position.

use ipc_types::{GnssFix, GnssFixType, GnssProtocol};
use serde::Serialize;

use super::own_positions::{
    MS_PER_WEEK, OwnMessage, OwnPlace, OwnPosition, OwnPositions, OwnTime, US_PER_DAY,
};
use super::reference::{MS_PER_DAY, ReferenceEpoch};

/// Mean Earth radius, m (IUGG). Over the centimetres compared here the sphere's distance differs
/// from the ellipsoid's by under 0.5 %.
const EARTH_RADIUS_M: f64 = 6_371_008.8;
/// A published position "agrees" with the reference within this horizontal distance, m: well
/// above the resolution either decoder keeps (NMEA's 1e-4 to 1e-7 minutes, UBX's 1e-7°, about
/// 1 cm at most), far below any receiver's error.
pub const AGREE_M: f64 = 0.01;
/// WGS84 semi-major axis, m.
const WGS84_A_M: f64 = 6_378_137.0;
/// WGS84 flattening.
const WGS84_F: f64 = 1.0 / 298.257_223_563;

/// How one capture's published fixes compare with its reference epochs.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct Score {
    /// Reference epochs (gpsd's fixes with a time).
    pub reference_epochs: usize,
    /// Every fix the decoder published, with a position or not.
    pub published: usize,
    /// Published fixes with a satellite position (2-D or better).
    pub published_with_position: usize,
    /// Published fixes with a position that fall on a reference epoch (each reference epoch
    /// matched at most once).
    pub matched: usize,
    /// Published fixes with a position at a time gpsd reported no fix for, or a second fix for
    /// an epoch already matched.
    pub unmatched: usize,
    /// Matched fixes within [`AGREE_M`] of the reference horizontally.
    pub within_1cm: usize,
    /// Largest horizontal distance of a matched fix from its reference, m.
    pub worst_horizontal_m: Option<f64>,
    /// Largest altitude difference of a matched fix from the reference's altitude above mean sea
    /// level, m, where both have one.
    pub worst_vertical_m: Option<f64>,
}

/// The key a fix's time is compared on: the UTC time of day for NMEA (what its sentences
/// carry), the GPS time of week for UBX (NAV-PVT's iTOW), both in ms.
pub fn fix_key_ms(fix: &GnssFix) -> (u8, u64) {
    let ms = (fix.receiver_time_us + 500) / 1_000;
    if fix.protocol == GnssProtocol::Ubx as u8 {
        (fix.protocol, ms)
    } else {
        (fix.protocol, ms % u64::from(MS_PER_DAY))
    }
}

/// The same key of a reference epoch, for a fix of `protocol`.
fn reference_key_ms(epoch: &ReferenceEpoch, protocol: u8) -> u64 {
    if protocol == GnssProtocol::Ubx as u8 {
        epoch.time.gps_time_of_week_ms()
    } else {
        u64::from(epoch.time.ms_of_day)
    }
}

/// Whether a fix carries a satellite position (2-D, 3-D, differential, RTK).
pub fn has_position(fix: &GnssFix) -> bool {
    GnssFixType::from_u8(fix.fix_type)
        .is_some_and(|t| !matches!(t, GnssFixType::NoFix | GnssFixType::DeadReckoning))
}

/// Matches `fixes` to `reference` by time key and compares the positions of the pairs.
///
/// A time of day repeats every day and a time of week every week: a fix goes to the first
/// reference epoch of its key not matched yet, which is exact for captures shorter than a day.
pub fn score(reference: &[ReferenceEpoch], fixes: &[GnssFix]) -> Score {
    let mut result = Score {
        reference_epochs: reference.len(),
        published: fixes.len(),
        ..Score::default()
    };
    let mut taken = vec![false; reference.len()];
    for fix in fixes.iter().filter(|f| has_position(f)) {
        result.published_with_position += 1;
        let (protocol, key) = fix_key_ms(fix);
        let found = reference
            .iter()
            .enumerate()
            .position(|(i, e)| !taken[i] && reference_key_ms(e, protocol) == key);
        let Some(i) = found else {
            result.unmatched += 1;
            continue;
        };
        taken[i] = true;
        result.matched += 1;
        let epoch = &reference[i];
        let horizontal = horizontal_m(fix, epoch);
        if horizontal <= AGREE_M {
            result.within_1cm += 1;
        }
        result.worst_horizontal_m = Some(worst(result.worst_horizontal_m, horizontal));
        if let Some(alt) = epoch.alt_msl_m.filter(|_| fix.altitude_m.is_finite()) {
            let vertical = (fix.altitude_m - alt).abs();
            result.worst_vertical_m = Some(worst(result.worst_vertical_m, vertical));
        }
    }
    result
}

/// Horizontal distance of a fix from its reference epoch, m: from gpsd's latitude and longitude,
/// or from its ECEF position where it reports one, whichever is nearer. gpsd's two positions of
/// one report can disagree: for a receiver sending NAV-SOL alone its latitude and longitude repeat
/// an earlier epoch's while the ECEF follows the receiver; where a receiver sends NAV-PVT and a
/// separate ECEF message, the ECEF may be another message's. A fix that agrees with either is a
/// reading of the same bytes.
fn horizontal_m(fix: &GnssFix, epoch: &ReferenceEpoch) -> f64 {
    let geodetic = haversine_m(
        fix.latitude_rad,
        fix.longitude_rad,
        epoch.lat_deg.to_radians(),
        epoch.lon_deg.to_radians(),
    );
    match epoch.ecef_m {
        Some(ecef) => geodetic.min(horizontal_from_ecef_m(
            fix.latitude_rad,
            fix.longitude_rad,
            ecef,
        )),
        None => geodetic,
    }
}

/// Horizontal distance, m, of the point at geodetic `lat`, `lon` (radians, WGS84) from an ECEF
/// position `ecef` (m): the height is taken from `ecef` itself (its component along the local
/// vertical at `lat`, `lon`), so that only the horizontal difference is left. A fix whose height
/// is above mean sea level, or missing, is thereby compared on its horizontal position alone.
pub fn horizontal_from_ecef_m(lat: f64, lon: f64, ecef: [f64; 3]) -> f64 {
    let base = ecef_from_geodetic(lat, lon, 0.0);
    let up = [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()];
    let h: f64 = (0..3).map(|i| (ecef[i] - base[i]) * up[i]).sum();
    let at_height = ecef_from_geodetic(lat, lon, h);
    (0..3)
        .map(|i| (ecef[i] - at_height[i]).powi(2))
        .sum::<f64>()
        .sqrt()
}

/// ECEF position, m, of geodetic `lat`, `lon` (radians) and height `h` above the WGS84
/// ellipsoid (m).
fn ecef_from_geodetic(lat: f64, lon: f64, h: f64) -> [f64; 3] {
    let e2 = WGS84_F * (2.0 - WGS84_F);
    let n = WGS84_A_M / (1.0 - e2 * lat.sin().powi(2)).sqrt();
    [
        (n + h) * lat.cos() * lon.cos(),
        (n + h) * lat.cos() * lon.sin(),
        (n * (1.0 - e2) + h) * lat.sin(),
    ]
}

/// The larger, a NaN counting as larger than anything (a position that is not a number is the
/// worst disagreement there is).
fn worst(so_far: Option<f64>, value: f64) -> f64 {
    match so_far {
        Some(w) if w.is_nan() || w >= value => w,
        _ => value,
    }
}

/// Great-circle distance between two points given in radians, m.
pub fn haversine_m(lat1: f64, lon1: f64, lat2: f64, lon2: f64) -> f64 {
    let dlat = lat2 - lat1;
    let dlon = lon2 - lon1;
    let a = (dlat / 2.0).sin().powi(2) + lat1.cos() * lat2.cos() * (dlon / 2.0).sin().powi(2);
    2.0 * EARTH_RADIUS_M * a.sqrt().clamp(0.0, 1.0).asin()
}

/// An NMEA fix and a sentence are of the same epoch when their UTC times of day differ by at most
/// this, µs: sentences carry hundredths or thousandths of a second, so a difference below 10 ms is
/// only a difference of rounding.
pub const OWN_SAME_TIME_US: u64 = 10_000;

/// How one capture's published fixes compare with the capture's own position messages of the same
/// receiver time ([`super::own_positions`]): a check of the product's readers against the bytes
/// themselves, beside gpsd's decode.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct OwnScore {
    /// Position messages in the capture (good checksum, a fix, readable fields).
    pub own_positions: usize,
    /// Position sentences set aside for a missing or wrong checksum.
    pub own_bad_checksum: usize,
    /// Position messages whose status, quality or fix type says "no fix".
    pub own_no_fix: usize,
    /// Position messages with an empty or unreadable field.
    pub own_unreadable: usize,
    /// Published fixes with a position for which the capture has a position message of the same
    /// receiver time.
    pub fixes_with_own_position: usize,
    /// Of those, fixes within [`AGREE_M`] horizontally of the epoch's full solution message, or
    /// without one of another position message of it (see [`score_own`]).
    pub fixes_within_1cm_of_own: usize,
    /// Published fixes with a position for which the capture has no position message of that
    /// time, or whose latitude or longitude is not a number.
    pub fixes_without_own_position: usize,
    /// The fix farthest from its nearest own position message of the same time.
    pub worst_own: Option<OwnWorst>,
}

/// A fix's distance from the nearest of the capture's own position messages of its time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OwnWorst {
    /// Horizontal distance, m.
    pub horizontal_m: f64,
    /// The nearest message.
    pub message: OwnMessage,
    /// The fix's receiver time, µs (UTC time of day for NMEA, GPS time of week for UBX).
    pub receiver_time_us: u64,
}

/// Compares every published fix with a position with the capture's `own` position messages of
/// the same receiver time (NMEA: UTC time of day within [`OWN_SAME_TIME_US`]; UBX: iTOW equal in
/// ms; a time the receiver repeats later is matched epoch by epoch, in order): the fix agrees
/// when it lies within [`AGREE_M`] of the epoch's full solution (GGA, GNS, NAV-PVT, NAV-POSLLH)
/// where the receiver sent one, else of one of its other position messages (RMC, GLL, NAV-SOL).
pub fn score_own(own: &OwnPositions, fixes: &[GnssFix]) -> OwnScore {
    let mut result = OwnScore {
        own_positions: own.positions.len(),
        own_bad_checksum: own.bad_checksum,
        own_no_fix: own.no_fix,
        own_unreadable: own.unreadable,
        ..OwnScore::default()
    };
    let occurrence = occurrences(&own.positions);
    // Fixes scored so far per receiver time: the k-th fix of a time is the k-th epoch of it.
    let mut fixes_of_time: Vec<(OwnTime, usize)> = Vec::new();
    for fix in fixes.iter().filter(|f| has_position(f)) {
        let nearest = if fix.latitude_rad.is_finite() && fix.longitude_rad.is_finite() {
            let same_time_at = |i: &usize| same_time(fix, own.positions[*i].time);
            let epoch = (0..own.positions.len()).find(same_time_at).map(|first| {
                let time = own.positions[first].time;
                let k = match fixes_of_time.iter_mut().find(|(t, _)| *t == time) {
                    Some((_, n)) => {
                        *n += 1;
                        *n - 1
                    }
                    None => {
                        fixes_of_time.push((time, 1));
                        0
                    }
                };
                let last = (0..own.positions.len())
                    .filter(same_time_at)
                    .map(|i| occurrence[i])
                    .max()
                    .unwrap_or(0);
                k.min(last)
            });
            // The receiver's full solution (GGA, GNS, NAV-PVT, NAV-POSLLH) where it sent one
            // for the epoch: a fix that took a coarser sentence's position instead (RMC and GLL
            // often carry fewer decimals) does not agree.
            let of_epoch = || {
                own.positions
                    .iter()
                    .zip(&occurrence)
                    .filter(|(p, o)| same_time(fix, p.time) && Some(**o) == epoch)
                    .map(|(p, _)| p)
            };
            let primary = of_epoch().any(|p| p.message.is_full_solution());
            of_epoch()
                .filter(|p| !primary || p.message.is_full_solution())
                .map(|p| (own_distance_m(fix, p), p.message))
                .min_by(|a, b| a.0.total_cmp(&b.0))
        } else {
            None
        };
        let Some((horizontal_m, message)) = nearest else {
            result.fixes_without_own_position += 1;
            continue;
        };
        result.fixes_with_own_position += 1;
        if horizontal_m <= AGREE_M {
            result.fixes_within_1cm_of_own += 1;
        }
        if result
            .worst_own
            .is_none_or(|w| horizontal_m.total_cmp(&w.horizontal_m).is_gt())
        {
            result.worst_own = Some(OwnWorst {
                horizontal_m,
                message,
                receiver_time_us: fix.receiver_time_us,
            });
        }
    }
    result
}

/// Which epoch of its receiver time each position message belongs to, counted from 0: a time
/// met again after messages of other times is a later epoch (a receiver whose clock stepped
/// back repeats its times with other positions).
fn occurrences(positions: &[OwnPosition]) -> Vec<usize> {
    let mut seen: Vec<(OwnTime, usize)> = Vec::new();
    let mut previous: Option<OwnTime> = None;
    positions
        .iter()
        .map(|p| {
            let occurrence = match seen.iter_mut().find(|(t, _)| *t == p.time) {
                Some((_, n)) if previous != Some(p.time) => {
                    *n += 1;
                    *n
                }
                Some((_, n)) => *n,
                None => {
                    seen.push((p.time, 0));
                    0
                }
            };
            previous = Some(p.time);
            occurrence
        })
        .collect()
}

/// Whether `fix` and a position message of receiver time `time` are of one epoch.
fn same_time(fix: &GnssFix, time: OwnTime) -> bool {
    let ubx = fix.protocol == GnssProtocol::Ubx as u8;
    match time {
        OwnTime::TimeOfWeekMs(itow) if ubx => {
            (fix.receiver_time_us + 500) / 1_000 % MS_PER_WEEK == itow % MS_PER_WEEK
        }
        OwnTime::UtcOfDayUs(us) if !ubx => {
            // A time of day wraps at midnight: the nearer way round counts.
            let d = (fix.receiver_time_us % US_PER_DAY).abs_diff(us % US_PER_DAY);
            d.min(US_PER_DAY - d) <= OWN_SAME_TIME_US
        }
        _ => false,
    }
}

/// Horizontal distance of `fix` from a position message, m: on the WGS84 ellipsoid's local radii
/// of curvature for latitude and longitude (a flat earth is exact to far below a centimetre over
/// the distances that decide agreement), or from an ECEF position as [`horizontal_from_ecef_m`].
fn own_distance_m(fix: &GnssFix, own: &OwnPosition) -> f64 {
    match own.place {
        OwnPlace::Geodetic { lat_deg, lon_deg } => {
            let dlat = fix.latitude_rad - lat_deg.to_radians();
            // The shorter way round at the antimeridian.
            let dlon = (fix.longitude_rad - lon_deg.to_radians() + std::f64::consts::PI)
                .rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            let north = dlat * rins_earth::meridian_radius(fix.latitude_rad);
            let east =
                dlon * rins_earth::prime_vertical_radius(fix.latitude_rad) * fix.latitude_rad.cos();
            north.hypot(east)
        }
        OwnPlace::Ecef(ecef) => horizontal_from_ecef_m(fix.latitude_rad, fix.longitude_rad, ecef),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gnss_captures::reference::parse_utc;

    fn epoch(time: &str, lat_deg: f64, lon_deg: f64) -> ReferenceEpoch {
        ReferenceEpoch {
            time: parse_utc(time).unwrap(),
            mode: 3,
            lat_deg,
            lon_deg,
            alt_msl_m: Some(100.0),
            ecef_m: None,
        }
    }

    fn fix(protocol: GnssProtocol, time_us: u64, lat_deg: f64, lon_deg: f64) -> GnssFix {
        GnssFix {
            fix_type: GnssFixType::Fix3d as u8,
            protocol: protocol as u8,
            receiver_time_us: time_us,
            latitude_rad: lat_deg.to_radians(),
            longitude_rad: lon_deg.to_radians(),
            altitude_m: 100.5,
            ..GnssFix::default()
        }
    }

    #[test]
    fn haversine_matches_the_arc_length() {
        // One arc-minute of latitude on the mean sphere: R·π/10800.
        let d = haversine_m(0.0, 0.0, (1.0_f64 / 60.0).to_radians(), 0.0);
        let expected = EARTH_RADIUS_M * std::f64::consts::PI / 10_800.0;
        assert!((d - expected).abs() < 1e-6, "{d} vs {expected}");
        // 1e-7° of latitude is about 1.1 cm.
        let d = haversine_m(0.7, 0.2, 0.7 + 1e-7_f64.to_radians(), 0.2);
        assert!((d - 0.011_119_5).abs() < 1e-6, "{d}");
    }

    #[test]
    fn nmea_fixes_match_by_time_of_day_and_ubx_by_time_of_week() {
        let reference = [
            epoch("2019-01-07T10:00:00Z", 45.0, 7.0),
            epoch("2019-01-07T10:00:01Z", 45.0, 7.0),
            epoch("2019-01-07T10:00:02Z", 45.0, 7.0),
        ];
        let day_ms = 10 * 3_600_000;
        // Monday, 18 leap seconds: the week's ms of 10:00:01 UTC.
        let tow_ms = 86_400_000 + day_ms + 1_000 + 18_000;
        // 1 mm north of the reference: agrees.
        let mm = 0.001 / EARTH_RADIUS_M;
        let fixes = [
            fix(
                GnssProtocol::Nmea,
                day_ms * 1_000,
                45.0 + mm.to_degrees(),
                7.0,
            ),
            fix(GnssProtocol::Ubx, tow_ms * 1_000, 45.0, 7.0 + 1e-6),
            // The same epoch again, and a time gpsd had no fix for.
            fix(GnssProtocol::Ubx, tow_ms * 1_000, 45.0, 7.0),
            fix(GnssProtocol::Nmea, (day_ms + 5_000) * 1_000, 45.0, 7.0),
            GnssFix {
                fix_type: GnssFixType::NoFix as u8,
                ..fix(GnssProtocol::Nmea, (day_ms + 2_000) * 1_000, 0.0, 0.0)
            },
        ];
        let s = score(&reference, &fixes);
        assert_eq!(s.reference_epochs, 3);
        assert_eq!(s.published, 5);
        assert_eq!(s.published_with_position, 4);
        assert_eq!(s.matched, 2);
        assert_eq!(s.unmatched, 2);
        assert_eq!(s.within_1cm, 1);
        // 1e-6° of longitude at 45°: 0.111 m · cos 45°.
        let expected = EARTH_RADIUS_M * 1e-6_f64.to_radians() * 45.0_f64.to_radians().cos();
        let worst = s.worst_horizontal_m.unwrap();
        assert!((worst - expected).abs() < 1e-6, "{worst} vs {expected}");
        assert!((s.worst_vertical_m.unwrap() - 0.5).abs() < 1e-9);
    }

    #[test]
    fn a_position_that_is_not_a_number_is_the_worst() {
        let reference = [epoch("2019-01-07T10:00:00Z", 45.0, 7.0)];
        let fixes = [fix(GnssProtocol::Nmea, 36_000_000_000, f64::NAN, 7.0)];
        let s = score(&reference, &fixes);
        assert_eq!((s.matched, s.within_1cm), (1, 0));
        assert!(s.worst_horizontal_m.unwrap().is_nan());
        assert_eq!(worst(Some(f64::NAN), 3.0).to_bits(), f64::NAN.to_bits());
    }

    #[test]
    fn a_point_1_cm_east_of_an_ecef_position_is_1_cm_away() {
        let (lat, lon) = (53.563_f64.to_radians(), (-113.44_f64).to_radians());
        let at = ecef_from_geodetic(lat, lon, 635.0);
        assert!(horizontal_from_ecef_m(lat, lon, at) < 1e-6);
        let east = [-lon.sin(), lon.cos(), 0.0];
        let moved = [0, 1, 2].map(|i| at[i] + 0.01 * east[i]);
        let d = horizontal_from_ecef_m(lat, lon, moved);
        assert!((d - 0.01).abs() < 1e-6, "{d}");
    }

    #[test]
    fn height_does_not_count_against_an_ecef_position() {
        let (lat, lon) = ((-34.9_f64).to_radians(), 138.6_f64.to_radians());
        let up = [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()];
        let base = ecef_from_geodetic(lat, lon, 28.0);
        let raised = [0, 1, 2].map(|i| base[i] + 10.0 * up[i]);
        let d = horizontal_from_ecef_m(lat, lon, raised);
        assert!(d < 1e-6, "{d}");
    }

    #[test]
    fn an_ecef_reference_is_compared_beside_its_latitude_and_longitude() {
        // gpsd's latitude and longitude are a kilometre off (a repeated first epoch); its ECEF is
        // the fix's own position.
        let (lat, lon) = (45.0_f64, 7.0_f64);
        let mut reference = epoch("2019-01-07T10:00:00Z", lat + 0.01, lon);
        reference.ecef_m = Some(ecef_from_geodetic(
            lat.to_radians(),
            lon.to_radians(),
            300.0,
        ));
        let fixes = [fix(GnssProtocol::Nmea, 36_000_000_000, lat, lon)];
        let s = score(&[reference], &fixes);
        assert_eq!((s.matched, s.within_1cm), (1, 1));
        assert!(s.worst_horizontal_m.unwrap() < 1e-6);
    }

    fn own(message: OwnMessage, time: OwnTime, lat_deg: f64, lon_deg: f64) -> OwnPosition {
        OwnPosition {
            message,
            time,
            place: OwnPlace::Geodetic { lat_deg, lon_deg },
        }
    }

    #[test]
    fn fixes_are_compared_with_their_captures_own_messages_of_the_same_time() {
        let day_us = 36_000_000_000_u64;
        // 1 cm of latitude on the meridian at 45°, in degrees.
        let cm_deg = (0.01 / rins_earth::meridian_radius(45.0_f64.to_radians())).to_degrees();
        let (lat, lon) = (45.0_f64, 7.0_f64);
        let ecef = ecef_from_geodetic(lat.to_radians(), (lon + 1e-6).to_radians(), 250.0);
        let own_positions = OwnPositions {
            positions: vec![
                // An RMC with 4 decimals 5 mm off, and the GGA of the same second exact.
                own(
                    OwnMessage::Rmc,
                    OwnTime::UtcOfDayUs(day_us + 4_000),
                    lat + 0.5 * cm_deg,
                    lon,
                ),
                own(OwnMessage::Gga, OwnTime::UtcOfDayUs(day_us), lat, lon),
                // A second later: 2 cm off.
                own(
                    OwnMessage::Gga,
                    OwnTime::UtcOfDayUs(day_us + 1_000_000),
                    lat + 2.0 * cm_deg,
                    lon,
                ),
                own(OwnMessage::NavPvt, OwnTime::TimeOfWeekMs(5_000), lat, lon),
                OwnPosition {
                    message: OwnMessage::NavSol,
                    time: OwnTime::TimeOfWeekMs(6_000),
                    place: OwnPlace::Ecef(ecef),
                },
            ],
            bad_checksum: 1,
            ..OwnPositions::default()
        };
        let fixes = [
            fix(GnssProtocol::Nmea, day_us + 5_000, lat, lon),
            fix(GnssProtocol::Nmea, day_us + 1_000_000, lat, lon),
            // 20 ms from any sentence, a NaN, and a UBX time that only an NMEA sentence has.
            fix(GnssProtocol::Nmea, day_us + 20_000, lat, lon),
            fix(GnssProtocol::Nmea, day_us, f64::NAN, lon),
            fix(GnssProtocol::Ubx, day_us, lat, lon),
            // iTOW equal after rounding to ms; NAV-SOL's ECEF 1e-6° of longitude east.
            fix(GnssProtocol::Ubx, 5_000_400, lat, lon),
            fix(GnssProtocol::Ubx, 6_000_000, lat, lon),
            GnssFix {
                fix_type: GnssFixType::NoFix as u8,
                ..fix(GnssProtocol::Ubx, 5_000_000, lat, lon)
            },
        ];
        let s = score_own(&own_positions, &fixes);
        assert_eq!((s.own_positions, s.own_bad_checksum), (5, 1));
        assert_eq!(s.fixes_with_own_position, 4);
        assert_eq!(s.fixes_within_1cm_of_own, 2);
        assert_eq!(s.fixes_without_own_position, 3);
        // The worst: NAV-SOL, 1e-6° of longitude at 45° (about 7.9 cm), beyond the GGA's 2 cm.
        let worst = s.worst_own.unwrap();
        let expected = 1e-6_f64.to_radians()
            * rins_earth::prime_vertical_radius(45.0_f64.to_radians())
            * 45.0_f64.to_radians().cos();
        assert_eq!(worst.message, OwnMessage::NavSol);
        assert_eq!(worst.receiver_time_us, 6_000_000);
        assert!((worst.horizontal_m - expected).abs() < 1e-5, "{worst:?}");
    }

    #[test]
    fn a_fix_must_agree_with_its_epochs_full_solution_and_a_repeated_time_is_a_later_epoch() {
        let t_us = 36_000_000_000_u64;
        let t = OwnTime::UtcOfDayUs(t_us);
        let cm_deg = (0.01 / rins_earth::meridian_radius(45.0_f64.to_radians())).to_degrees();
        let (lat, lon) = (45.0_f64, 7.0_f64);
        let own_positions = OwnPositions {
            positions: vec![
                // The first epoch of time t: a coarse RMC 3 m off, and its GGA.
                own(OwnMessage::Rmc, t, lat + 300.0 * cm_deg, lon),
                own(OwnMessage::Gga, t, lat, lon),
                own(
                    OwnMessage::Gga,
                    OwnTime::UtcOfDayUs(36_001_000_000),
                    lat,
                    lon,
                ),
                // The clock stepped back: time t again, 40 m further on, an RMC only.
                own(OwnMessage::Rmc, t, lat + 4000.0 * cm_deg, lon),
            ],
            ..OwnPositions::default()
        };
        // A fix that took the RMC's position where the GGA was sent does not agree; the second
        // epoch of t is scored against its own RMC, not the first epoch's GGA.
        let coarse = [
            fix(GnssProtocol::Nmea, t_us, lat + 300.0 * cm_deg, lon),
            fix(GnssProtocol::Nmea, t_us, lat + 4000.0 * cm_deg, lon),
        ];
        let s = score_own(&own_positions, &coarse);
        assert_eq!(
            (s.fixes_with_own_position, s.fixes_within_1cm_of_own),
            (2, 1)
        );
        let worst = s.worst_own.expect("a worst fix");
        assert_eq!(worst.message, OwnMessage::Gga);
        assert!((worst.horizontal_m - 3.0).abs() < 1e-3, "{worst:?}");
        let exact = [
            fix(GnssProtocol::Nmea, t_us, lat, lon),
            fix(GnssProtocol::Nmea, t_us, lat + 4000.0 * cm_deg, lon),
        ];
        assert_eq!(score_own(&own_positions, &exact).fixes_within_1cm_of_own, 2);
    }

    #[test]
    fn a_time_of_day_matches_across_midnight() {
        let just_before = OwnTime::UtcOfDayUs(US_PER_DAY - 5_000);
        let at_midnight = fix(GnssProtocol::Nmea, US_PER_DAY + 2_000, 0.0, 0.0);
        assert!(same_time(&at_midnight, just_before));
        assert!(!same_time(&at_midnight, OwnTime::UtcOfDayUs(20_000)));
    }
}
