//! Attitude helpers: rotation-vector exponential and ZYX (aerospace) Euler angles.
//!
//! Quaternions rotate body (FRD) → NED, Hamilton convention, `q = [w, x, y, z]`.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// Below this rotation angle the exponential uses its Taylor series; the truncation error
/// (θ⁴/384 ≈ 3e-27) is far below f64 resolution, and `sin(θ/2)/θ` would lose digits.
const SMALL_ANGLE_RAD: f64 = 1e-6;

/// Exact quaternion exponential of a rotation vector φ (axis × angle, rad):
/// `exp(½ φ) = [cos(|φ|/2), sin(|φ|/2) φ/|φ|]`.
pub fn rotation_vector_to_quaternion(phi: &Vector3<f64>) -> UnitQuaternion<f64> {
    let angle = phi.norm();
    let (w, scale) = if angle < SMALL_ANGLE_RAD {
        let a2 = angle * angle;
        (1.0 - a2 / 8.0, 0.5 - a2 / 48.0)
    } else {
        let half = 0.5 * angle;
        (half.cos(), half.sin() / angle)
    };
    UnitQuaternion::new_unchecked(Quaternion::new(
        w,
        scale * phi.x,
        scale * phi.y,
        scale * phi.z,
    ))
}

/// Roll, pitch, yaw (rad) of a body→NED quaternion, ZYX aerospace sequence: `C_nb = Rz(yaw) Ry(pitch) Rx(roll)`.
///
/// Pitch is in [−π/2, π/2], roll and yaw in (−π, π]. At pitch = ±π/2 roll and yaw are not separable.
pub fn euler_from_quaternion(q: &UnitQuaternion<f64>) -> [f64; 3] {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    [roll, pitch, yaw]
}

/// Body→NED quaternion from roll, pitch, yaw (rad), ZYX aerospace sequence:
/// `q = q_z(yaw) ⊗ q_y(pitch) ⊗ q_x(roll)`.
pub fn quaternion_from_euler(roll: f64, pitch: f64, yaw: f64) -> UnitQuaternion<f64> {
    let (sr, cr) = (0.5 * roll).sin_cos();
    let (sp, cp) = (0.5 * pitch).sin_cos();
    let (sy, cy) = (0.5 * yaw).sin_cos();
    UnitQuaternion::new_unchecked(Quaternion::new(
        cr * cp * cy + sr * sp * sy,
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
    ))
}

/// Wraps an angle to (−π, π].
pub fn wrap_pi(angle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    // Angles already in range are returned bit-exact, so a zero increment never moves them.
    if angle > -PI && angle <= PI {
        return angle;
    }
    let wrapped = (angle + PI).rem_euclid(TAU) - PI;
    if wrapped == -PI { PI } else { wrapped }
}

/// Quaternion as `[w, x, y, z]`.
pub fn quaternion_to_array(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    #[test]
    fn exponential_matches_axis_angle_for_large_and_tiny_angles() {
        for &angle in &[2.5, 0.3, 1e-3, 1e-7, 0.0] {
            let axis = Vector3::new(1.0, -2.0, 0.5).normalize();
            let q = rotation_vector_to_quaternion(&(axis * angle));
            let (s, c) = (0.5 * angle).sin_cos();
            assert!((q.w - c).abs() < 1e-15);
            let v = Vector3::new(q.i, q.j, q.k);
            assert!((v - axis * s).norm() < 1e-15);
            assert!((q.as_ref().norm() - 1.0).abs() < 1e-15);
        }
    }

    #[test]
    fn convention_matches_nalgebra_zyx_and_frd_ned_geometry() {
        let q = quaternion_from_euler(0.1, -0.4, 2.0);
        let reference = UnitQuaternion::from_euler_angles(0.1, -0.4, 2.0);
        assert!(q.angle_to(&reference) < 1e-14);
        // Yaw 90°: the nose (body x) points east.
        let east = quaternion_from_euler(0.0, 0.0, FRAC_PI_2) * Vector3::x();
        assert!((east - Vector3::y()).norm() < 1e-15);
        // Pitch up 10°: the nose points above the horizon, i.e. a negative down component.
        let nose = quaternion_from_euler(0.0, 10f64.to_radians(), 0.0) * Vector3::x();
        assert!((nose.z + 10f64.to_radians().sin()).abs() < 1e-15);
        // Roll right 30°: the right wing (body y) points down.
        let wing = quaternion_from_euler(30f64.to_radians(), 0.0, 0.0) * Vector3::y();
        assert!((wing.z - 0.5).abs() < 1e-15);
    }

    #[test]
    fn wrap_pi_range() {
        assert_eq!(wrap_pi(PI), PI);
        assert_eq!(wrap_pi(-PI), PI);
        assert!((wrap_pi(3.0 * PI / 2.0) + PI / 2.0).abs() < 1e-15);
        assert!((wrap_pi(-7.0) - (-7.0 + 2.0 * PI)).abs() < 1e-15);
    }
}
