//! Attitude in the angles people read: roll, pitch and yaw of a body→NED quaternion.

/// Roll, pitch, yaw in degrees (ZYX Euler angles, aerospace convention) of the body (FRD) → NED
/// quaternion `q` = [w, x, y, z] (Hamilton, scalar first). `q` need not be of unit norm: it is
/// normalised first, so a sample that drifted off the unit sphere still reads right; a zero or
/// non-finite quaternion gives NaN angles. Pitch is clamped to ±90° where rounding would take the
/// arcsine's argument past ±1.
pub fn euler_deg(q: [f64; 4]) -> [f64; 3] {
    let norm = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    let [w, x, y, z] = q.map(|c| c / norm);
    let roll = (2.0 * (w * x + y * z)).atan2(1.0 - 2.0 * (x * x + y * y));
    let pitch = (2.0 * (w * y - z * x)).clamp(-1.0, 1.0).asin();
    let yaw = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
    [roll.to_degrees(), pitch.to_degrees(), yaw.to_degrees()]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quaternion of yaw ψ, then pitch θ, then roll φ (radians): q = qz(ψ)·qy(θ)·qx(φ).
    fn from_euler(roll: f64, pitch: f64, yaw: f64) -> [f64; 4] {
        let (sr, cr) = (roll / 2.0).sin_cos();
        let (sp, cp) = (pitch / 2.0).sin_cos();
        let (sy, cy) = (yaw / 2.0).sin_cos();
        [
            cr * cp * cy + sr * sp * sy,
            sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
        ]
    }

    #[test]
    fn angles_of_a_known_attitude_come_back() {
        for (r, p, y) in [(0.1, 0.2, -0.3), (-2.5, -1.2, 3.0), (0.0, 0.0, 1.5)] {
            let e = euler_deg(from_euler(r, p, y));
            for (got, want) in e.iter().zip([r, p, y]) {
                assert!(
                    (got - f64::to_degrees(want)).abs() < 1e-9,
                    "{e:?} vs {r} {p} {y}"
                );
            }
        }
    }

    #[test]
    fn a_quaternion_off_the_unit_sphere_reads_as_its_direction() {
        let q = from_euler(0.3, -0.4, 2.0).map(|c| c * 1.7);
        let e = euler_deg(q);
        assert!((e[2] - 2.0f64.to_degrees()).abs() < 1e-9, "{e:?}");
    }

    #[test]
    fn a_90_degree_yaw_about_down() {
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let e = euler_deg([h, 0.0, 0.0, h]);
        assert!(e[0].abs() < 1e-12 && e[1].abs() < 1e-12, "{e:?}");
        assert!((e[2] - 90.0).abs() < 1e-12, "{e:?}");
    }
}
