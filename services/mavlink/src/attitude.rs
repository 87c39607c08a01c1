//! ATTITUDE_QUATERNION: the body (FRD) → NED attitude, Hamilton, scalar first — MAVLink's own
//! convention, so the quaternion goes across unchanged — with the body rates.

use ipc_types::NavState;

use crate::dialect::ATTITUDE_QUATERNION_DATA;
use crate::time_boot_ms;

/// The attitude of `nav` with `body_rate_rps` (FRD, rad/s: the fused rate less the estimated gyro
/// bias).
pub fn attitude_quaternion(nav: &NavState, body_rate_rps: [f64; 3]) -> ATTITUDE_QUATERNION_DATA {
    let [w, x, y, z] = nav.quaternion;
    ATTITUDE_QUATERNION_DATA {
        time_boot_ms: time_boot_ms(nav),
        q1: w as f32,
        q2: x as f32,
        q3: y as f32,
        q4: z as f32,
        rollspeed: body_rate_rps[0] as f32,
        pitchspeed: body_rate_rps[1] as f32,
        yawspeed: body_rate_rps[2] as f32,
        // The solution is the body's own attitude: no offset representation.
        repr_offset_q: [0.0; 4],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quaternion_rates_and_time_go_across() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let mut nav = NavState {
            quaternion: [h, 0.0, 0.0, h],
            ..NavState::default()
        };
        nav.header.origin_rx_ns = 12_345_678_901;
        let m = attitude_quaternion(&nav, [0.1, -0.2, 0.3]);
        assert_eq!(m.time_boot_ms, 12_345);
        assert_eq!([m.q1, m.q2, m.q3, m.q4], [h as f32, 0.0, 0.0, h as f32]);
        assert_eq!([m.rollspeed, m.pitchspeed, m.yawspeed], [0.1, -0.2, 0.3]);
    }
}
