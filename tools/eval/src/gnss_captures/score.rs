//! Published fixes against the reference epochs: matched by the receiver's time, compared by
//! position.

use ipc_types::{GnssFix, GnssFixType, GnssProtocol};
use serde::Serialize;

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
}
