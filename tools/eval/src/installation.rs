//! Relative rotation between two rigidly mounted IMUs from paired vectors (Wahba's problem).
//!
//! Every point of a rigid body turns at the same angular rate, so two gyro triads on one airframe
//! measure the same vector in two frames: `ω_ref = R ω_other` (+ noise, biases). The rotation that
//! minimises `Σ |r_k − R o_k|²` is, with `B = Σ r_k o_kᵀ = U S Vᵀ`,
//! `R = U diag(1, 1, det U · det V) Vᵀ` (Markley 1988): the determinant term keeps R proper when
//! the best orthogonal fit would be a reflection. R is unique when B has rank ≥ 2, i.e. when the
//! vectors span at least two directions.

use nalgebra::{Matrix3, Rotation3, SVD, UnitQuaternion, Vector3};
use thiserror::Error;

/// B's second singular value below this fraction of the first counts as rank < 2.
pub const MIN_SINGULAR_RATIO: f64 = 1e-9;

/// Why no rotation could be estimated.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InstallationError {
    /// The two vector lists differ in length.
    #[error("{reference} reference vectors but {other} others: they must be paired")]
    LengthMismatch {
        /// Vectors in the reference frame.
        reference: usize,
        /// Vectors in the other frame.
        other: usize,
    },
    /// No vectors were given.
    #[error("no vector pairs")]
    Empty,
    /// A pair holds a NaN or an infinity.
    #[error("pair {index} is not finite")]
    NonFinite {
        /// Index of the first such pair.
        index: usize,
    },
    /// The vectors span fewer than two directions (second singular value below
    /// [`MIN_SINGULAR_RATIO`] of the first), so the rotation is not unique.
    #[error(
        "the vectors span fewer than two directions (singular values {singular_values:?}): the rotation is not unique"
    )]
    Degenerate {
        /// Singular values of the pairs' correlation matrix, largest first.
        singular_values: [f64; 3],
    },
    /// The singular value decomposition did not converge.
    #[error("the singular value decomposition did not converge")]
    NoConvergence,
}

/// The rotation R (other → reference frame) minimising `Σ |reference_k − R other_k|²`.
pub fn estimate_relative_rotation(
    reference: &[[f64; 3]],
    other: &[[f64; 3]],
) -> Result<Rotation3<f64>, InstallationError> {
    if reference.len() != other.len() {
        return Err(InstallationError::LengthMismatch {
            reference: reference.len(),
            other: other.len(),
        });
    }
    if reference.is_empty() {
        return Err(InstallationError::Empty);
    }
    let mut b = Matrix3::zeros();
    for (index, (r, o)) in reference.iter().zip(other).enumerate() {
        if !r.iter().chain(o).all(|x| x.is_finite()) {
            return Err(InstallationError::NonFinite { index });
        }
        b += Vector3::from(*r) * Vector3::from(*o).transpose();
    }
    wahba(&b)
}

/// Solves Wahba's problem for the attitude profile matrix `b = Σ r_k o_kᵀ`.
pub fn wahba(b: &Matrix3<f64>) -> Result<Rotation3<f64>, InstallationError> {
    let svd = SVD::try_new(*b, true, true, f64::EPSILON, 10_000)
        .ok_or(InstallationError::NoConvergence)?;
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Err(InstallationError::NoConvergence);
    };
    let s = svd.singular_values;
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| s[j].total_cmp(&s[i]));
    let singular_values = order.map(|i| s[i]);
    // Written so that NaN singular values are degenerate too.
    let well_posed = singular_values[1] > MIN_SINGULAR_RATIO * singular_values[0];
    if !well_posed {
        return Err(InstallationError::Degenerate { singular_values });
    }
    let mut d = Matrix3::identity();
    d[(order[2], order[2])] = (u.determinant() * v_t.determinant()).signum();
    Ok(Rotation3::from_matrix_unchecked(u * d * v_t))
}

/// Rotation vector (axis × angle, rad) of `r`, accurate at small angles too: from the
/// quaternion as `2·atan2(|v|, w)` (with w ≥ 0), where `acos` of the matrix trace loses half the
/// digits near zero.
pub fn rotation_vector(r: &Rotation3<f64>) -> Vector3<f64> {
    let q = UnitQuaternion::from_rotation_matrix(r);
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let s = v.norm();
    if s == 0.0 {
        return Vector3::zeros();
    }
    v * (2.0 * s.atan2(w) / s)
}

/// Angle between two rotations, rad (see [`rotation_vector`]).
pub fn angle_between(a: &Rotation3<f64>, b: &Rotation3<f64>) -> f64 {
    rotation_vector(&(a.inverse() * b)).norm()
}

/// RMS of `|reference_k − R other_k|` (same units as the vectors); `None` for no pairs.
pub fn residual_rms(
    reference: &[[f64; 3]],
    other: &[[f64; 3]],
    rotation: &Rotation3<f64>,
) -> Option<f64> {
    let n = reference.len().min(other.len());
    if n == 0 {
        return None;
    }
    let sum: f64 = reference
        .iter()
        .zip(other)
        .map(|(r, o)| (Vector3::from(*r) - rotation * Vector3::from(*o)).norm_squared())
        .sum();
    Some((sum / n as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    fn rotate_all(r: &Rotation3<f64>, v: &[[f64; 3]]) -> Vec<[f64; 3]> {
        v.iter().map(|x| (r * Vector3::from(*x)).into()).collect()
    }

    fn random_vectors(n: usize, seed: u64) -> Vec<[f64; 3]> {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        (0..n)
            .map(|_| [0; 3].map(|_| normal.sample(&mut rng)))
            .collect()
    }

    #[test]
    fn recovers_a_known_rotation_to_1e_9() {
        let truth = Rotation3::from_euler_angles(0.3, -1.1, 2.5);
        let other = random_vectors(50, 1);
        let reference = rotate_all(&truth, &other);
        let r = estimate_relative_rotation(&reference, &other).unwrap();
        assert!(
            angle_between(&r, &truth) < 1e-9,
            "{}",
            angle_between(&r, &truth)
        );
        assert!(residual_rms(&reference, &other, &r).unwrap() < 1e-9);
    }

    #[test]
    fn two_directions_suffice_one_does_not() {
        let truth = Rotation3::from_euler_angles(0.0, 0.2, -0.4);
        let other = vec![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [2.0, 0.0, 0.0]];
        let reference = rotate_all(&truth, &other);
        let r = estimate_relative_rotation(&reference, &other).unwrap();
        assert!(angle_between(&r, &truth) < 1e-9);
        let collinear = vec![[1.0, 1.0, 0.0], [-2.0, -2.0, 0.0]];
        let e = estimate_relative_rotation(&rotate_all(&truth, &collinear), &collinear);
        assert!(
            matches!(e, Err(InstallationError::Degenerate { .. })),
            "{e:?}"
        );
    }

    #[test]
    fn result_is_a_proper_rotation_even_for_mirrored_data() {
        // A reflection fits the data exactly; the estimate must still have det +1.
        let other = random_vectors(20, 2);
        let mirrored: Vec<[f64; 3]> = other.iter().map(|v| [v[0], v[1], -v[2]]).collect();
        let r = estimate_relative_rotation(&mirrored, &other).unwrap();
        assert!((r.matrix().determinant() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn bad_input_is_an_error() {
        assert_eq!(
            estimate_relative_rotation(&[[1.0; 3]], &[]),
            Err(InstallationError::LengthMismatch {
                reference: 1,
                other: 0
            })
        );
        assert_eq!(
            estimate_relative_rotation(&[], &[]),
            Err(InstallationError::Empty)
        );
        assert_eq!(
            estimate_relative_rotation(&[[1.0, 0.0, f64::NAN]], &[[1.0; 3]]),
            Err(InstallationError::NonFinite { index: 0 })
        );
    }

    #[test]
    fn noisy_estimate_error_shrinks_like_noise_over_root_n() {
        // Vectors with unit variance per component and noise σ per component: the information on
        // each small-angle axis is Σ(|o|² − o_i²)/σ² ≈ 2N/σ², so the angle error (three axes) is
        // about σ·√(3/(2N)); allow 5 of those.
        let truth = Rotation3::from_euler_angles(0.05, 0.02, -0.03);
        let n = 5000;
        let sigma = 0.05;
        let other = random_vectors(n, 3);
        let noise = random_vectors(n, 4);
        let reference: Vec<[f64; 3]> = rotate_all(&truth, &other)
            .iter()
            .zip(&noise)
            .map(|(r, e)| [0, 1, 2].map(|i| r[i] + sigma * e[i]))
            .collect();
        let r = estimate_relative_rotation(&reference, &other).unwrap();
        let bound = 5.0 * sigma * (1.5 / n as f64).sqrt();
        assert!(
            angle_between(&r, &truth) < bound,
            "{} >= {bound}",
            angle_between(&r, &truth)
        );
    }

    proptest! {
        #[test]
        fn any_rotation_is_recovered(
            roll in -3.1f64..3.1, pitch in -1.5f64..1.5, yaw in -3.1f64..3.1, seed in 0u64..1000
        ) {
            let truth = Rotation3::from_euler_angles(roll, pitch, yaw);
            let other = random_vectors(10, seed);
            let reference = rotate_all(&truth, &other);
            let r = estimate_relative_rotation(&reference, &other).unwrap();
            prop_assert!(angle_between(&r, &truth) < 1e-9);
        }
    }
}
