//! Plausibility of a decoded fix: a message with a valid checksum can still carry values no
//! receiver on a small aircraft could measure.

use ipc_types::{GnssFix, GnssFixType};

/// Highest plausible altitude, m.
const MAX_ALTITUDE_M: f64 = 50_000.0;
/// Lowest plausible altitude, m.
const MIN_ALTITUDE_M: f64 = -1_000.0;
/// Fastest plausible speed per axis, m/s.
const MAX_SPEED_MPS: f64 = 600.0;

/// Whether `fix` is usable as far as its values go: a fix without a position is always
/// plausible (it says so); one with a position needs latitude, longitude and altitude in range
/// (a 2-D fix may have no altitude, NaN, and then no vertical accuracy either),
/// a velocity in range when it has one, and accuracies that are finite and not negative.
pub fn is_plausible(fix: &GnssFix) -> bool {
    let positioned = GnssFixType::from_u8(fix.fix_type).is_some_and(|t| t != GnssFixType::NoFix);
    if !positioned {
        return true;
    }
    let in_range = |x: f64, lo: f64, hi: f64| x.is_finite() && (lo..=hi).contains(&x);
    let pi = std::f64::consts::PI;
    // A 2-D fix may carry no height (NaN: an RMC, or an ECEF solution without mean sea level);
    // a height it does carry must be in range.
    let no_height = fix.fix_type == GnssFixType::Fix2d as u8 && fix.altitude_m.is_nan();
    let position = in_range(fix.latitude_rad, -pi / 2.0, pi / 2.0)
        && in_range(fix.longitude_rad, -pi, pi)
        && (no_height || in_range(fix.altitude_m, MIN_ALTITUDE_M, MAX_ALTITUDE_M));
    let velocity = fix.velocity_valid == 0
        || fix
            .velocity_ned_mps
            .iter()
            .all(|&v| in_range(v, -MAX_SPEED_MPS, MAX_SPEED_MPS));
    let vertical = (no_height && fix.vertical_accuracy_m.is_nan())
        || in_range(fix.vertical_accuracy_m, 0.0, 1e6);
    let accuracy = vertical
        && [fix.horizontal_accuracy_m, fix.speed_accuracy_mps, fix.hdop]
            .iter()
            .all(|&a| in_range(a, 0.0, 1e6));
    position && velocity && accuracy
}
