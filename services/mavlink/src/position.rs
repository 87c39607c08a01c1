//! GLOBAL_POSITION_INT (WGS84 degrees ×1e7, altitude in mm, velocity in cm/s, heading in
//! centidegrees) and LOCAL_POSITION_NED (metres from the local origin).

use ipc_types::NavState;
use rins_earth::attitude::euler_deg;

use crate::dialect::{GLOBAL_POSITION_INT_DATA, LOCAL_POSITION_NED_DATA};
use crate::local_frame::LocalOrigin;
use crate::time_boot_ms;

/// `value × scale` rounded to the nearest integer of `T`, saturating at its range (a speed beyond
/// ±327 m/s or a position that is not finite must not wrap into a plausible one).
fn scaled<T: TryFrom<i64> + Copy>(value: f64, scale: f64, min: T, max: T) -> T {
    let v = (value * scale).round();
    if v.is_nan() {
        return min;
    }
    let clamped = v.clamp(i64::MIN as f64, i64::MAX as f64) as i64;
    T::try_from(clamped).unwrap_or(if clamped < 0 { min } else { max })
}

/// Heading of a body → NED quaternion [w, x, y, z], centidegrees in [0, 36000); `u16::MAX`, the
/// message's "unknown", for a quaternion that gives no angle.
fn heading_cdeg(q: [f64; 4]) -> u16 {
    let [_, _, yaw_deg] = euler_deg(q);
    let cdeg = (yaw_deg.rem_euclid(360.0) * 100.0).round();
    if !cdeg.is_finite() {
        return u16::MAX;
    }
    // 359.995° rounds up to 36000: that is north again.
    if cdeg >= 36_000.0 { 0 } else { cdeg as u16 }
}

/// The global position of `nav`; `relative_alt` is the altitude above `origin`.
pub fn global_position_int(nav: &NavState, origin: &LocalOrigin) -> GLOBAL_POSITION_INT_DATA {
    let [vn, ve, vd] = nav.velocity_ned_mps;
    GLOBAL_POSITION_INT_DATA {
        time_boot_ms: time_boot_ms(nav),
        lat: scaled(nav.latitude_rad.to_degrees(), 1e7, i32::MIN, i32::MAX),
        lon: scaled(nav.longitude_rad.to_degrees(), 1e7, i32::MIN, i32::MAX),
        alt: scaled(nav.altitude_m, 1e3, i32::MIN, i32::MAX),
        relative_alt: scaled(nav.altitude_m - origin.altitude_m, 1e3, i32::MIN, i32::MAX),
        vx: scaled(vn, 100.0, i16::MIN, i16::MAX),
        vy: scaled(ve, 100.0, i16::MIN, i16::MAX),
        vz: scaled(vd, 100.0, i16::MIN, i16::MAX),
        hdg: heading_cdeg(nav.quaternion),
    }
}

/// The position of `nav` in the local NED frame of `origin`, with its NED velocity.
pub fn local_position_ned(nav: &NavState, origin: &LocalOrigin) -> LOCAL_POSITION_NED_DATA {
    let [x, y, z] = origin.ned(nav.latitude_rad, nav.longitude_rad, nav.altitude_m);
    let [vx, vy, vz] = nav.velocity_ned_mps;
    LOCAL_POSITION_NED_DATA {
        time_boot_ms: time_boot_ms(nav),
        x: x as f32,
        y: y as f32,
        z: z as f32,
        vx: vx as f32,
        vy: vy as f32,
        vz: vz as f32,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nav_at(lat_deg: f64, lon_deg: f64, alt: f64) -> NavState {
        NavState {
            latitude_rad: lat_deg.to_radians(),
            longitude_rad: lon_deg.to_radians(),
            altitude_m: alt,
            velocity_ned_mps: [1.234, -5.678, 0.5],
            ..NavState::default()
        }
    }

    #[test]
    fn global_position_is_scaled_as_the_message_defines() {
        let origin = LocalOrigin::new(47.0f64.to_radians(), 8.0f64.to_radians(), 400.0);
        let m = global_position_int(&nav_at(47.1234567, 8.7654321, 488.25), &origin);
        assert_eq!((m.lat, m.lon), (471_234_567, 87_654_321));
        assert_eq!((m.alt, m.relative_alt), (488_250, 88_250));
        assert_eq!((m.vx, m.vy, m.vz), (123, -568, 50));
        assert_eq!(m.hdg, 0);
    }

    #[test]
    fn out_of_range_values_saturate_instead_of_wrapping() {
        let mut nav = nav_at(0.0, 0.0, f64::NAN);
        nav.velocity_ned_mps = [400.0, -400.0, f64::INFINITY];
        let m = global_position_int(&nav, &LocalOrigin::new(0.0, 0.0, 0.0));
        assert_eq!((m.vx, m.vy, m.vz), (i16::MAX, i16::MIN, i16::MAX));
        assert_eq!(m.alt, i32::MIN);
    }

    #[test]
    fn heading_is_the_yaw_in_centidegrees_from_north() {
        for (yaw_deg, want) in [(0.0, 0), (30.0, 3000), (-90.0, 27000), (179.99, 17999)] {
            let half = f64::to_radians(yaw_deg) / 2.0;
            assert_eq!(
                heading_cdeg([half.cos(), 0.0, 0.0, half.sin()]),
                want,
                "{yaw_deg}"
            );
        }
    }

    #[test]
    fn local_position_is_metres_from_the_origin() {
        let origin = LocalOrigin::new(47.0f64.to_radians(), 8.0f64.to_radians(), 400.0);
        let nav = nav_at(47.0, 8.0, 450.0);
        let m = local_position_ned(&nav, &origin);
        assert_eq!((m.x, m.y, m.z), (0.0, 0.0, -50.0));
        assert_eq!((m.vx, m.vy, m.vz), (1.234, -5.678, 0.5));
    }
}
