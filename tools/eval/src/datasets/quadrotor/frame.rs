//! Axis convention of the Xsens DOT recordings and the conversion to the product's FRD body frame.
//!
//! The sensor frame is right-handed with z out of the top face: level and at rest the
//! accelerometer reads `Acc_Z ≈ +9.8` (the specific force is the reaction to gravity, pointing up).
//! Its x axis points forward on this airframe (nose-down flight gives `Acc_X < 0`, `Euler_Y > 0`).
//! FRD is the same frame turned 180° about x: `x' = x`, `y' = −y`, `z' = −z` (a proper rotation,
//! so rates transform like any vector). Level at rest, FRD specific force is `[0, 0, −g]`.
//!
//! Euler angles: the recorded `Euler_X/Y/Z` are the Z-Y-X angles of the sensor in a z-up world
//! frame. Turning both the body and the world frame by 180° about x gives
//! `C' = Rx(π) Rz(ψ) Ry(θ) Rx(φ) Rx(π) = Rz(−ψ) Ry(−θ) Rx(φ)`, so in FRD/NED terms roll = `Euler_X`,
//! pitch = `−Euler_Y`, yaw = `−Euler_Z` (+ an unknown offset: the Xsens heading reference is its
//! own magnetometer and differs between the four units). Both relations are checked on the real
//! files by the tests (gyro against Euler-angle rates, specific force when level).

/// A vector of the Xsens sensor frame (z up) in FRD.
pub fn xsens_to_frd(v: [f64; 3]) -> [f64; 3] {
    [v[0], -v[1], -v[2]]
}

/// FRD roll, pitch, yaw (rad, ZYX) from the recorded Xsens Euler angles (degrees).
pub fn xsens_euler_to_frd(euler_deg: [f64; 3]) -> [f64; 3] {
    [
        euler_deg[0].to_radians(),
        -euler_deg[1].to_radians(),
        -euler_deg[2].to_radians(),
    ]
}

/// Body rate (FRD, rad/s) of ZYX Euler angles `[φ, θ, ψ]` changing at `[φ̇, θ̇, ψ̇]`:
/// `ω = [φ̇ − ψ̇ sinθ, θ̇ cosφ + ψ̇ sinφ cosθ, −θ̇ sinφ + ψ̇ cosφ cosθ]`.
pub fn body_rate_from_euler_rates(euler: [f64; 3], rates: [f64; 3]) -> [f64; 3] {
    let (sr, cr) = euler[0].sin_cos();
    let (sp, cp) = euler[1].sin_cos();
    let [dr, dp, dy] = rates;
    [
        dr - dy * sp,
        dp * cr + dy * sr * cp,
        -dp * sr + dy * cr * cp,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, Vector3};

    #[test]
    fn conversion_is_a_proper_rotation_about_x() {
        let r = Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
        let v = [0.3, -1.2, 9.8];
        let expected = r * Vector3::from(v);
        let got = Vector3::from(xsens_to_frd(v));
        assert!((expected - got).norm() < 1e-12);
        // Level at rest: Acc_Z = +g becomes f_z = −g.
        assert_eq!(xsens_to_frd([0.0, 0.0, 9.8]), [0.0, -0.0, -9.8]);
    }

    #[test]
    fn euler_conversion_matches_the_frame_change() {
        // C' = Rx(π) C Rx(π) for C = Rz(ψ) Ry(θ) Rx(φ) in the z-up frames.
        let (phi, theta, psi) = (0.2, -0.4, 1.1);
        let c = Rotation3::from_euler_angles(phi, theta, psi);
        let flip = Rotation3::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
        let c_frd = flip * c * flip;
        let [r, p, y] =
            xsens_euler_to_frd([phi.to_degrees(), theta.to_degrees(), psi.to_degrees()]);
        let expected = Rotation3::from_euler_angles(r, p, y);
        assert!(crate::installation::angle_between(&c_frd, &expected) < 1e-12);
    }

    #[test]
    fn body_rate_of_pure_yaw_and_roll() {
        // Yaw rate only, level: ω = [0, 0, ψ̇]. Roll rate only: ω = [φ̇, 0, 0].
        assert_eq!(
            body_rate_from_euler_rates([0.0; 3], [0.0, 0.0, 0.5]),
            [0.0, 0.0, 0.5]
        );
        assert_eq!(
            body_rate_from_euler_rates([0.0, 0.0, 2.0], [0.3, 0.0, 0.0]),
            [0.3, 0.0, 0.0]
        );
    }

    #[test]
    fn body_rate_matches_the_derivative_of_the_rotation() {
        // ω× = Cᵀ Ċ, by central differences of C(t) for a smooth Euler trajectory.
        let euler = |t: f64| [0.3 * t.sin(), -0.2 + 0.1 * t, 1.0 + 0.5 * t * t];
        let rates = |t: f64| [0.3 * t.cos(), 0.1, t];
        let c = |t: f64| {
            let e = euler(t);
            Rotation3::from_euler_angles(e[0], e[1], e[2])
        };
        let (t, h) = (0.7, 1e-6);
        let delta = c(t).inverse() * c(t + h) * (c(t).inverse() * c(t - h)).inverse();
        let omega = crate::installation::rotation_vector(&delta) / (2.0 * h);
        let got = body_rate_from_euler_rates(euler(t), rates(t));
        assert!(
            (omega - Vector3::from(got)).norm() < 1e-5,
            "{omega} {got:?}"
        );
    }
}
