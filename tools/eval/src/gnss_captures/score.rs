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
        let horizontal = haversine_m(
            fix.latitude_rad,
            fix.longitude_rad,
            epoch.lat_deg.to_radians(),
            epoch.lon_deg.to_radians(),
        );
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
}
