//! rins's frames (NED world, FRD body) to ROS's (REP 103: ENU world, FLU body).
//!
//! ```text
//! v_enu = M v_ned,   M = [[0, 1, 0], [1, 0, 0], [0, 0, −1]]   (north ↔ east, down → up)
//! v_flu = B v_frd,   B = diag(1, −1, −1)                        (right → left, down → up)
//! C_enu←flu = M · C_ned←frd · B
//! ```
//!
//! So a heading ψ clockwise from north is a yaw of π/2 − ψ counter-clockwise from east, a pitch
//! nose-up is a negative pitch about the left axis, and a roll right-wing-down stays positive.

use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

const NED_TO_ENU: Matrix3<f64> = Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0);
const FRD_TO_FLU: Matrix3<f64> = Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0);

/// A world vector NED → ENU.
pub fn ned_to_enu([n, e, d]: [f64; 3]) -> [f64; 3] {
    [e, n, -d]
}

/// A body vector FRD → FLU.
pub fn frd_to_flu([f, r, d]: [f64; 3]) -> [f64; 3] {
    [f, -r, -d]
}

/// The attitude body (FRD) → NED, scalar first, as body (FLU) → ENU, scalar first.
pub fn attitude_enu_flu(q_ned_frd: [f64; 4]) -> [f64; 4] {
    let [w, x, y, z] = q_ned_frd;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    let c = NED_TO_ENU * q.to_rotation_matrix().into_inner() * FRD_TO_FLU;
    let out = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(c));
    [out.w, out.i, out.j, out.k]
}

/// A body vector in FLU turned into the ENU world by the attitude (FLU → ENU, scalar first).
pub fn flu_to_enu(q_enu_flu: [f64; 4], v_flu: [f64; 3]) -> [f64; 3] {
    let [w, x, y, z] = q_enu_flu;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    (q * Vector3::from(v_flu)).into()
}

/// The diagonal of a NED covariance (or of the variances of rotations about N, E, D) in ENU order.
pub fn ned_variances_to_enu([n, e, d]: [f64; 3]) -> [f64; 3] {
    [e, n, d]
}

/// The world covariance diag(`variances_ned`) seen in the body FLU: `C Σ Cᵀ` with C the
/// world (NED) → body (FLU) rotation of the attitude `q_ned_frd`; row-major 3 × 3.
pub fn ned_covariance_in_flu(q_ned_frd: [f64; 4], variances_ned: [f64; 3]) -> [[f64; 3]; 3] {
    let [w, x, y, z] = q_ned_frd;
    let q = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    let c = FRD_TO_FLU * q.to_rotation_matrix().into_inner().transpose();
    let s = c * Matrix3::from_diagonal(&Vector3::from(variances_ned)) * c.transpose();
    std::array::from_fn(|i| std::array::from_fn(|j| s[(i, j)]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// Scalar-first quaternion of roll, pitch, yaw (Z-Y-X intrinsic).
    fn from_euler(roll: f64, pitch: f64, yaw: f64) -> [f64; 4] {
        let q = UnitQuaternion::from_euler_angles(roll, pitch, yaw);
        [q.w, q.i, q.j, q.k]
    }

    fn euler(q: [f64; 4]) -> [f64; 3] {
        let [w, x, y, z] = q;
        let (r, p, yw) =
            UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z)).euler_angles();
        [r, p, yw]
    }

    #[test]
    fn known_attitudes_read_as_ros_reads_them() {
        let d = f64::to_radians;
        // (roll, pitch, heading) in NED/FRD → (roll, pitch, yaw) in ENU/FLU.
        for (ned, enu) in [
            ([0.0, 0.0, 0.0], [0.0, 0.0, FRAC_PI_2]),
            ([0.0, 0.0, FRAC_PI_2], [0.0, 0.0, 0.0]),
            ([0.0, 0.0, d(30.0)], [0.0, 0.0, d(60.0)]),
            ([d(10.0), 0.0, 0.0], [d(10.0), 0.0, FRAC_PI_2]),
            ([0.0, d(10.0), 0.0], [0.0, d(-10.0), FRAC_PI_2]),
            ([d(5.0), d(-7.0), d(120.0)], [d(5.0), d(7.0), d(-30.0)]),
        ] {
            let got = euler(attitude_enu_flu(from_euler(ned[0], ned[1], ned[2])));
            for k in 0..3 {
                assert!(
                    (got[k] - enu[k]).abs() < 1e-12,
                    "{ned:?}: {got:?} against {enu:?}"
                );
            }
        }
    }

    #[test]
    fn vectors_and_covariances_keep_their_meaning() {
        // Flying north-east and climbing, heading north-east: forward and up in the body.
        let q = from_euler(0.0, 0.0, std::f64::consts::FRAC_PI_4);
        let v_ned = [1.0, 1.0, -0.5];
        assert_eq!(ned_to_enu(v_ned), [1.0, 1.0, 0.5]);
        let q_enu = attitude_enu_flu(q);
        let [w, x, y, z] = q;
        let v_frd: [f64; 3] = (UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))
            .inverse()
            * Vector3::from(v_ned))
        .into();
        let back = flu_to_enu(q_enu, frd_to_flu(v_frd));
        for k in 0..3 {
            assert!((back[k] - ned_to_enu(v_ned)[k]).abs() < 1e-12, "{back:?}");
        }
        assert!((frd_to_flu(v_frd)[0] - 2f64.sqrt()).abs() < 1e-12);
        // A north-only variance, heading east: it lies across the body, along its left axis.
        let s = ned_covariance_in_flu(from_euler(0.0, 0.0, FRAC_PI_2), [4.0, 0.0, 0.0]);
        assert!(
            (s[1][1] - 4.0).abs() < 1e-12 && s[0][0].abs() < 1e-12,
            "{s:?}"
        );
        assert_eq!(ned_variances_to_enu([1.0, 2.0, 3.0]), [2.0, 1.0, 3.0]);
    }
}
