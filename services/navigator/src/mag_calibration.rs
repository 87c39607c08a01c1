//! Magnetometer hard- and soft-iron calibration from samples taken in many orientations (\[R3\]
//! eq. 2–6).
//!
//! **Model.** The sensor reads `m = A h + b`: the body-frame field h distorted by the soft-iron
//! matrix A and offset by the hard iron b. The true field is `h = A⁻¹ (m − b)` and has the constant
//! magnitude F of the local field, so every sample lies on the ellipsoid
//! `(m − b)ᵀ Q (m − b) = F²` with `Q = A⁻ᵀ A⁻¹`.
//!
//! **Fit.** The samples are centred on their mean μ and scaled by their RMS spread s, so that every
//! column of the design matrix is of order one, and the general quadric
//! `xᵀ M x + pᵀ x + c = 0` (10 coefficients, x the scaled sample) is fitted by total least squares:
//! the coefficient vector is the right singular vector of the smallest singular value of the design
//! matrix (faer SVD). The quadric is an ellipsoid only if M is definite. Completing the square gives
//! the centre `x₀ = −½ M⁻¹ p` and `(x − x₀)ᵀ (M / k) (x − x₀) = 1` with `k = x₀ᵀ M x₀ − c > 0`; back
//! in microtesla, `b = μ + s x₀` and `Q = F² M / (k s²)`.
//!
//! **Correction.** Any W with `WᵀW = Q` maps the samples onto the sphere of radius F; W is only
//! defined up to a rotation (`R W` fits as well), the rotation the data cannot see. The symmetric
//! square root `W = Q^{1/2}` (eigen-decomposition) is chosen: it equals A⁻¹ when A is symmetric and
//! otherwise adds the least rotation. F is not observable from the samples either; it is given by the
//! caller (the local field magnitude) or else taken as the mean of `|m − b|`, the raw magnitude with
//! the hard iron removed, so the correction keeps the sensor's own average scale.
//!
//! **Checks.** Each refusal names its reason. Too few samples. Samples that span too few directions:
//! the smallest variance of the unit directions, about the mean before the fit and of the corrected
//! field after it, must reach [`MIN_DIRECTION_SPREAD`] (a vehicle turned about one axis only sweeps
//! a cone and leaves the quadric undetermined). Samples that fit a family of quadrics about equally
//! well (two full turns about two fixed axes span every direction but lie on a one-parameter
//! family): the two smallest singular values must be [`MIN_SINGULAR_GAP`] apart. A quadric that is
//! not an ellipsoid (M not definite). The residual `|W (m − b)| − F` is reported as RMS and max.

use faer::Mat;
use nalgebra::{Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

/// Fewest samples accepted: twice the nine free parameters of the ellipsoid, and then some.
pub const MIN_SAMPLES: usize = 20;
/// Largest accepted |component| of a sample, µT (the Earth field is about 25–65 µT; a sensor
/// reading 1 T is broken, and larger values would overflow the squares of the fit).
pub const MAX_SAMPLE_UT: f64 = 1e6;
/// Smallest accepted eigenvalue of the covariance of the unit field directions. Directions spread
/// evenly over the whole sphere give 1/3 on every axis; a vehicle turned about one axis only gives 0
/// (its directions sweep a cone). Below this the fitted soft iron along the poorly covered axis is
/// mostly noise.
pub const MIN_DIRECTION_SPREAD: f64 = 0.02;
/// Smallest accepted ratio of the second-smallest to the smallest singular value of the design
/// matrix. Near 1, a whole family of quadrics fits the samples about equally well (two circles, for
/// instance, lie on a one-parameter family) and the chosen one is set by the noise; the angle between
/// the fitted and the true coefficient vector is about the inverse of this ratio.
pub const MIN_SINGULAR_GAP: f64 = 10.0;
/// Smallest accepted ratio of the smallest to the largest eigenvalue of M, the squared ratio of the
/// shortest to the longest ellipsoid axis: an axis ratio beyond 100 is not a soft-iron distortion.
const MIN_AXIS_RATIO_SQUARED: f64 = 1e-4;

/// Hard-iron offset and soft-iron correction: `h = W (m − b)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MagCalibration {
    /// Hard iron b, body frame, µT: subtracted from the raw reading first.
    pub hard_iron_ut: [f64; 3],
    /// Soft-iron correction W (row-major, dimensionless): applied after the hard iron is removed.
    pub soft_iron_correction: [[f64; 3]; 3],
}

impl Default for MagCalibration {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl MagCalibration {
    /// No correction.
    pub const IDENTITY: Self = Self {
        hard_iron_ut: [0.0; 3],
        soft_iron_correction: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    /// The corrected field `W (m − b)`, µT.
    pub fn apply(&self, raw_ut: [f64; 3]) -> [f64; 3] {
        let d: [f64; 3] = std::array::from_fn(|i| raw_ut[i] - self.hard_iron_ut[i]);
        self.soft_iron_correction
            .map(|row| row[0] * d[0] + row[1] * d[1] + row[2] * d[2])
    }
}

/// A calibration and how well it explains the samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MagFit {
    /// Hard iron and soft-iron correction, to apply to raw readings.
    pub calibration: MagCalibration,
    /// Magnitude F the corrected field is scaled to, µT.
    pub field_ut: f64,
    /// True when F came from the caller, false when it is the mean of `|m − b|`.
    pub field_given: bool,
    /// Samples used.
    pub samples: usize,
    /// RMS of `|W (m − b)| − F` over the samples, µT.
    pub residual_rms_ut: f64,
    /// Largest `| |W (m − b)| − F |`, µT.
    pub residual_max_ut: f64,
    /// Smallest eigenvalue of the covariance of the corrected unit directions (1/3 for the whole
    /// sphere, at least [`MIN_DIRECTION_SPREAD`]).
    pub direction_spread: f64,
}

/// Why a set of samples gives no calibration.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MagCalibrationError {
    /// Fewer than [`MIN_SAMPLES`] samples.
    #[error("{count} samples: at least {MIN_SAMPLES} are needed")]
    TooFewSamples {
        /// Samples given.
        count: usize,
    },
    /// A sample component is not finite or beyond [`MAX_SAMPLE_UT`].
    #[error("sample {index} axis {axis} = {value} µT: must be finite, |x| <= {MAX_SAMPLE_UT:e}")]
    SampleOutOfRange {
        /// 0-based index of the sample.
        index: usize,
        /// Axis 0, 1 or 2 (x, y, z).
        axis: usize,
        /// The reading, µT.
        value: f64,
    },
    /// The field magnitude given by the caller is not finite and positive.
    #[error("field_ut = {value}: must be finite and > 0 µT")]
    InvalidField {
        /// The magnitude given, µT.
        value: f64,
    },
    /// The samples do not cover enough directions for the soft iron to be observable.
    #[error(
        "the samples span too few directions (smallest direction variance {spread:.4}, at least \
         {MIN_DIRECTION_SPREAD} is needed; a whole sphere gives 0.333): rotate the vehicle \
         through more orientations"
    )]
    InsufficientCoverage {
        /// Smallest eigenvalue of the covariance of the sample directions, about their mean before
        /// the fit, corrected after it (1/3 for the whole sphere).
        spread: f64,
    },
    /// The fit is ill-determined: more than one ellipsoid explains the samples.
    #[error(
        "the samples fit a family of ellipsoids rather than one (second-smallest singular value \
         of the fit only {gap:.1} times the smallest, at least {MIN_SINGULAR_GAP} is needed): \
         rotate the vehicle through more orientations"
    )]
    Underdetermined {
        /// Second-smallest singular value of the fit over the smallest.
        gap: f64,
    },
    /// The fitted quadric is not an ellipsoid (mixed signs or too elongated).
    #[error(
        "the samples do not lie on an ellipsoid: the fitted quadric has eigenvalues \
         {:.3e}, {:.3e}, {:.3e} (an ellipsoid needs one sign and an axis ratio below 100)",
        eigenvalues[0], eigenvalues[1], eigenvalues[2]
    )]
    NotEllipsoid {
        /// Eigenvalues of the quadric's second-order (3×3) part, in the fit's normalised coordinates.
        eigenvalues: [f64; 3],
    },
    /// A decomposition in the fit (SVD, eigenvalues, square root) failed or gave non-finite values.
    #[error("the singular value decomposition of the quadric fit did not converge")]
    Decomposition,
}

/// Fits hard and soft iron to `samples` (raw readings, µT) taken while the vehicle is turned through
/// many orientations. `field_ut` is the local field magnitude; `None` scales the correction to the
/// mean of `|m − b|`.
pub fn fit_ellipsoid(
    samples: &[[f64; 3]],
    field_ut: Option<f64>,
) -> Result<MagFit, MagCalibrationError> {
    if samples.len() < MIN_SAMPLES {
        return Err(MagCalibrationError::TooFewSamples {
            count: samples.len(),
        });
    }
    check_samples(samples)?;
    if let Some(value) = field_ut
        && !(value.is_finite() && value > 0.0)
    {
        return Err(MagCalibrationError::InvalidField { value });
    }
    let points: Vec<Vector3<f64>> = samples.iter().map(|s| Vector3::from(*s)).collect();
    let mean = points.iter().sum::<Vector3<f64>>() / points.len() as f64;
    // Planar or collinear data leave the quadric undetermined: say so before fitting.
    let spread = direction_spread(points.iter().map(|p| p - mean));
    if spread.is_nan() || spread < MIN_DIRECTION_SPREAD {
        return Err(MagCalibrationError::InsufficientCoverage { spread });
    }
    let scale = (points
        .iter()
        .map(|p| (p - mean).norm_squared())
        .sum::<f64>()
        / points.len() as f64)
        .sqrt();
    let scaled: Vec<Vector3<f64>> = points.iter().map(|p| (p - mean) / scale).collect();
    let (centre, shape) = fit_quadric(&scaled)?;

    let hard_iron = mean + scale * centre;
    let field = match field_ut {
        Some(f) => f,
        None => points.iter().map(|p| (p - hard_iron).norm()).sum::<f64>() / points.len() as f64,
    };
    // (m − b)ᵀ shape (m − b) = s² on the ellipsoid; W = (F/s) shape^{1/2}.
    let correction = symmetric_sqrt(&shape)? * (field / scale);
    let corrected: Vec<Vector3<f64>> = points
        .iter()
        .map(|p| correction * (p - hard_iron))
        .collect();
    let spread = direction_spread(corrected.iter().copied());
    if spread.is_nan() || spread < MIN_DIRECTION_SPREAD {
        return Err(MagCalibrationError::InsufficientCoverage { spread });
    }
    let residuals = corrected.iter().map(|h| h.norm() - field);
    let (sum_sq, max) = residuals.fold((0.0, 0.0_f64), |(s, m), r| (s + r * r, m.max(r.abs())));
    let calibration = MagCalibration {
        hard_iron_ut: hard_iron.into(),
        soft_iron_correction: std::array::from_fn(|r| std::array::from_fn(|c| correction[(r, c)])),
    };
    let finite = calibration.hard_iron_ut.iter().all(|x| x.is_finite())
        && calibration
            .soft_iron_correction
            .iter()
            .flatten()
            .all(|x| x.is_finite());
    if !finite {
        return Err(MagCalibrationError::Decomposition);
    }
    Ok(MagFit {
        calibration,
        field_ut: field,
        field_given: field_ut.is_some(),
        samples: samples.len(),
        residual_rms_ut: (sum_sq / samples.len() as f64).sqrt(),
        residual_max_ut: max,
        direction_spread: spread,
    })
}

fn check_samples(samples: &[[f64; 3]]) -> Result<(), MagCalibrationError> {
    for (index, sample) in samples.iter().enumerate() {
        for (axis, &value) in sample.iter().enumerate() {
            if !(value.is_finite() && value.abs() <= MAX_SAMPLE_UT) {
                return Err(MagCalibrationError::SampleOutOfRange { index, axis, value });
            }
        }
    }
    Ok(())
}

/// Smallest eigenvalue of the covariance of the unit vectors along `vectors` (zero vectors skipped).
fn direction_spread(vectors: impl Iterator<Item = Vector3<f64>>) -> f64 {
    let mut n = 0usize;
    let mut sum = Vector3::zeros();
    let mut second = Matrix3::zeros();
    for v in vectors {
        let norm = v.norm();
        if !(norm > 0.0 && norm.is_finite()) {
            continue;
        }
        let u = v / norm;
        n += 1;
        sum += u;
        second += u * u.transpose();
    }
    if n < 3 {
        return 0.0;
    }
    let mean = sum / n as f64;
    let covariance = second / n as f64 - mean * mean.transpose();
    symmetric_eigen(&covariance).map_or(f64::NAN, |e| e.eigenvalues.min())
}

/// Eigen-decomposition of a symmetric 3×3 matrix; `None` if it does not converge (only possible
/// for non-finite entries, which would otherwise iterate for ever).
fn symmetric_eigen(a: &Matrix3<f64>) -> Option<SymmetricEigen<f64, nalgebra::U3>> {
    const MAX_ITERATIONS: usize = 100;
    SymmetricEigen::try_new(*a, f64::EPSILON, MAX_ITERATIONS)
}

/// Fits the quadric to the centred, scaled points; returns the centre x₀ and the shape matrix
/// `M / k`, with `(x − x₀)ᵀ (M / k) (x − x₀) = 1` on the ellipsoid.
fn fit_quadric(
    points: &[Vector3<f64>],
) -> Result<(Vector3<f64>, Matrix3<f64>), MagCalibrationError> {
    let design = Mat::<f64>::from_fn(points.len(), 10, |r, c| {
        let [x, y, z] = [points[r].x, points[r].y, points[r].z];
        match c {
            0 => x * x,
            1 => y * y,
            2 => z * z,
            3 => 2.0 * x * y,
            4 => 2.0 * x * z,
            5 => 2.0 * y * z,
            6 => x,
            7 => y,
            8 => z,
            _ => 1.0,
        }
    });
    let svd = design
        .thin_svd()
        .map_err(|_| MagCalibrationError::Decomposition)?;
    // Singular values are in nonincreasing order: the last column of V is the least-squares fit.
    let singular = svd.S().column_vector();
    let gap = singular[8] / singular[9];
    if gap.is_nan() || gap < MIN_SINGULAR_GAP {
        return Err(MagCalibrationError::Underdetermined { gap });
    }
    let v = svd.V();
    let theta: [f64; 10] = std::array::from_fn(|i| v[(i, 9)]);
    if !theta.iter().all(|t| t.is_finite()) {
        return Err(MagCalibrationError::Decomposition);
    }
    let m = Matrix3::new(
        theta[0], theta[3], theta[4], //
        theta[3], theta[1], theta[5], //
        theta[4], theta[5], theta[2],
    );
    let eigenvalues = symmetric_eigen(&m)
        .ok_or(MagCalibrationError::Decomposition)?
        .eigenvalues;
    let not_ellipsoid = || MagCalibrationError::NotEllipsoid {
        eigenvalues: eigenvalues.into(),
    };
    // The singular vector's sign is arbitrary: choose the one that makes M positive.
    let (sign, low, high) = if eigenvalues.max() <= 0.0 {
        (-1.0, -eigenvalues.max(), -eigenvalues.min())
    } else {
        (1.0, eigenvalues.min(), eigenvalues.max())
    };
    let (m, p, c) = (
        sign * m,
        sign * Vector3::new(theta[6], theta[7], theta[8]),
        sign * theta[9],
    );
    if !(low > 0.0 && low >= MIN_AXIS_RATIO_SQUARED * high) {
        return Err(not_ellipsoid());
    }
    let inverse = m.try_inverse().ok_or_else(not_ellipsoid)?;
    let centre = -0.5 * inverse * p;
    let k = centre.dot(&(m * centre)) - c;
    if !(k > 0.0 && k.is_finite()) {
        return Err(not_ellipsoid());
    }
    Ok((centre, m / k))
}

/// The symmetric positive square root of a positive definite matrix.
fn symmetric_sqrt(a: &Matrix3<f64>) -> Result<Matrix3<f64>, MagCalibrationError> {
    let eigen = symmetric_eigen(a).ok_or(MagCalibrationError::Decomposition)?;
    if !eigen.eigenvalues.iter().all(|&l| l > 0.0 && l.is_finite()) {
        return Err(MagCalibrationError::NotEllipsoid {
            eigenvalues: eigen.eigenvalues.into(),
        });
    }
    let root = Matrix3::from_diagonal(&eigen.eigenvalues.map(f64::sqrt));
    let w = eigen.eigenvectors * root * eigen.eigenvectors.transpose();
    Ok(0.5 * (w + w.transpose()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use rand_distr::StandardNormal;

    const FIELD_UT: f64 = 50.0;
    const HARD_IRON_UT: [f64; 3] = [12.0, -7.0, 30.0];
    const SOFT_IRON: [[f64; 3]; 3] = [[1.1, 0.05, 0.05], [0.05, 0.9, 0.05], [0.05, 0.05, 1.05]];

    fn unit(rng: &mut ChaCha8Rng) -> Vector3<f64> {
        loop {
            let v = Vector3::from_fn(|_, _| rng.sample::<f64, _>(StandardNormal));
            if v.norm() > 1e-6 {
                return v.normalize();
            }
        }
    }

    /// Readings `A h + b + noise` for `n` field directions drawn by `direction`.
    fn readings(
        n: usize,
        noise_ut: f64,
        seed: u64,
        soft_iron: [[f64; 3]; 3],
        hard_iron: [f64; 3],
        mut direction: impl FnMut(&mut ChaCha8Rng) -> Vector3<f64>,
    ) -> Vec<[f64; 3]> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let a = Matrix3::from_fn(|r, c| soft_iron[r][c]);
        let b = Vector3::from(hard_iron);
        (0..n)
            .map(|_| {
                let h = FIELD_UT * direction(&mut rng);
                let noise =
                    Vector3::from_fn(|_, _| noise_ut * rng.sample::<f64, _>(StandardNormal));
                (a * h + b + noise).into()
            })
            .collect()
    }

    fn sphere(n: usize, noise_ut: f64, seed: u64) -> Vec<[f64; 3]> {
        readings(n, noise_ut, seed, SOFT_IRON, HARD_IRON_UT, unit)
    }

    #[test]
    fn recovers_known_hard_and_soft_iron() {
        let samples = sphere(500, 0.1, 1);
        let fit = fit_ellipsoid(&samples, Some(FIELD_UT)).unwrap();
        let cal = fit.calibration;
        for (got, want) in cal.hard_iron_ut.iter().zip(HARD_IRON_UT) {
            assert!((got - want).abs() < 0.3, "hard iron {:?}", cal.hard_iron_ut);
        }
        // A is symmetric, so the symmetric correction is A⁻¹ itself.
        let inverse = Matrix3::from_fn(|r, c| SOFT_IRON[r][c])
            .try_inverse()
            .unwrap();
        for r in 0..3 {
            for c in 0..3 {
                let err = cal.soft_iron_correction[r][c] - inverse[(r, c)];
                assert!(err.abs() < 0.005, "W = {:?}", cal.soft_iron_correction);
            }
        }
        let sq: f64 = samples
            .iter()
            .map(|m| (Vector3::from(cal.apply(*m)).norm() - FIELD_UT).powi(2))
            .sum();
        let rms = (sq / samples.len() as f64).sqrt();
        assert!(rms < 0.5, "corrected magnitude RMS error {rms} µT");
        assert!((fit.residual_rms_ut - rms).abs() < 1e-9);
        assert!(
            fit.residual_max_ut < 0.5,
            "max residual {}",
            fit.residual_max_ut
        );
        assert!(
            fit.residual_rms_ut < 0.15,
            "RMS residual {}",
            fit.residual_rms_ut
        );
        assert!(
            fit.direction_spread > 0.25,
            "spread {}",
            fit.direction_spread
        );
        assert!(fit.field_given);
        assert_eq!(fit.samples, 500);
    }

    #[test]
    fn correction_is_symmetric() {
        let fit = fit_ellipsoid(&sphere(200, 0.1, 2), None).unwrap();
        let w = fit.calibration.soft_iron_correction;
        for (r, row) in w.iter().enumerate() {
            for (c, x) in row.iter().enumerate() {
                assert_eq!(*x, w[c][r]);
            }
        }
    }

    #[test]
    fn default_field_is_mean_magnitude_without_hard_iron() {
        let samples = sphere(500, 0.1, 3);
        let given = fit_ellipsoid(&samples, Some(FIELD_UT)).unwrap();
        let fit = fit_ellipsoid(&samples, None).unwrap();
        assert!(!fit.field_given);
        assert_eq!(fit.calibration.hard_iron_ut, given.calibration.hard_iron_ut);
        let b = Vector3::from(fit.calibration.hard_iron_ut);
        let mean = samples
            .iter()
            .map(|m| (Vector3::from(*m) - b).norm())
            .sum::<f64>()
            / samples.len() as f64;
        assert!((fit.field_ut - mean).abs() < 1e-9);
        // Same shape, other scale.
        let ratio = fit.field_ut / FIELD_UT;
        for (w, w0) in fit
            .calibration
            .soft_iron_correction
            .iter()
            .flatten()
            .zip(given.calibration.soft_iron_correction.iter().flatten())
        {
            assert!((w - ratio * w0).abs() < 1e-9);
        }
    }

    #[test]
    fn identity_leaves_reading_unchanged() {
        assert_eq!(
            MagCalibration::default().apply([1.0, -2.0, 3.5]),
            [1.0, -2.0, 3.5]
        );
    }

    #[test]
    fn too_few_samples_are_rejected() {
        let samples = sphere(MIN_SAMPLES - 1, 0.1, 4);
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert_eq!(err, MagCalibrationError::TooFewSamples { count: 19 });
        assert!(err.to_string().contains("19 samples: at least 20"));
        assert!(fit_ellipsoid(&sphere(MIN_SAMPLES, 0.1, 4), None).is_ok());
    }

    #[test]
    fn non_finite_sample_is_rejected_by_index() {
        let mut samples = sphere(100, 0.1, 5);
        samples[42][1] = f64::NAN;
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert!(matches!(
            err,
            MagCalibrationError::SampleOutOfRange { index: 42, axis: 1, value } if value.is_nan()
        ));
        assert!(err.to_string().contains("sample 42 axis 1 = NaN"));
        samples[42][1] = f64::INFINITY;
        assert!(fit_ellipsoid(&samples, None).is_err());
        samples[42][1] = 2e6;
        assert!(fit_ellipsoid(&samples, None).is_err());
    }

    #[test]
    fn invalid_field_is_rejected() {
        let samples = sphere(100, 0.1, 6);
        for value in [0.0, -50.0, f64::NAN, f64::INFINITY] {
            let err = fit_ellipsoid(&samples, Some(value)).unwrap_err();
            assert!(
                matches!(err, MagCalibrationError::InvalidField { .. }),
                "{err}"
            );
        }
    }

    #[test]
    fn rotation_about_one_axis_is_rejected_as_poor_coverage() {
        // Turning about the vertical only: the field (inclined 60°) sweeps a cone.
        let (s, c) = 60f64.to_radians().sin_cos();
        let samples = readings(300, 0.1, 7, SOFT_IRON, HARD_IRON_UT, |rng| {
            let yaw: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            Vector3::new(c * yaw.cos(), c * yaw.sin(), s)
        });
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert!(
            matches!(err, MagCalibrationError::InsufficientCoverage { .. }),
            "{err}"
        );
        assert!(
            err.to_string()
                .contains("rotate the vehicle through more orientations")
        );
    }

    #[test]
    fn small_cap_of_directions_is_rejected_as_poor_coverage() {
        // Tilts of at most about 15° from one attitude.
        let samples = readings(300, 0.1, 8, SOFT_IRON, HARD_IRON_UT, |rng| {
            let tilt: Vector3<f64> = 0.25
                * Vector3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    0.0,
                );
            (Vector3::z() + tilt).normalize()
        });
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert!(
            matches!(err, MagCalibrationError::InsufficientCoverage { .. }),
            "{err}"
        );
    }

    #[test]
    fn two_rotations_about_fixed_axes_are_rejected_as_underdetermined() {
        // A full turn in yaw and a full turn in roll: two circles of directions, which lie on a
        // one-parameter family of quadrics although they span every axis.
        let (s, c) = 60f64.to_radians().sin_cos();
        let samples = readings(400, 0.1, 10, SOFT_IRON, HARD_IRON_UT, |rng| {
            let (sa, ca) = rng.random_range(0.0..std::f64::consts::TAU).sin_cos();
            if rng.random_bool(0.5) {
                Vector3::new(c * ca, c * sa, s)
            } else {
                Vector3::new(c, s * sa, s * ca)
            }
        });
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert!(
            matches!(err, MagCalibrationError::Underdetermined { .. }),
            "{err}"
        );
        assert!(
            err.to_string()
                .contains("rotate the vehicle through more orientations")
        );
    }

    #[test]
    fn identical_samples_are_rejected_as_poor_coverage() {
        let samples = vec![[10.0, 20.0, 30.0]; 50];
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert!(
            matches!(err, MagCalibrationError::InsufficientCoverage { .. }),
            "{err}"
        );
    }

    #[test]
    fn hyperboloid_is_rejected_as_not_an_ellipsoid() {
        // x² + y² − z²/4 = 1 (one sheet), |z| <= 2: spans every direction but is no ellipsoid.
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let samples: Vec<[f64; 3]> = (0..400)
            .map(|_| {
                let z: f64 = rng.random_range(-2.0..2.0);
                let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                let r = (1.0 + z * z / 4.0).sqrt();
                [30.0 * r * phi.cos(), 30.0 * r * phi.sin(), 30.0 * z]
            })
            .collect();
        let err = fit_ellipsoid(&samples, None).unwrap_err();
        assert!(
            matches!(err, MagCalibrationError::NotEllipsoid { .. }),
            "{err}"
        );
        assert!(err.to_string().contains("do not lie on an ellipsoid"));
    }

    fn soft_iron_strategy() -> impl Strategy<Value = [[f64; 3]; 3]> {
        // Identity plus up to ±0.3 on every entry: a general (not symmetric) distortion.
        prop::array::uniform3(prop::array::uniform3(-0.3..0.3f64)).prop_map(|d| {
            std::array::from_fn(|r| {
                std::array::from_fn(|c| d[r][c] + if r == c { 1.0 } else { 0.0 })
            })
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// Whatever the soft iron (symmetric or not), the correction puts every noise-free
        /// reading back on the sphere of radius F.
        #[test]
        fn corrected_points_have_the_field_magnitude(
            soft_iron in soft_iron_strategy(),
            hard_iron in prop::array::uniform3(-40.0..40.0f64),
            seed in any::<u64>(),
        ) {
            let det = Matrix3::from_fn(|r, c| soft_iron[r][c]).determinant();
            prop_assume!(det.abs() > 0.2);
            let samples = readings(60, 0.0, seed, soft_iron, hard_iron, unit);
            let fit = fit_ellipsoid(&samples, Some(FIELD_UT)).unwrap();
            for m in &samples {
                let h = Vector3::from(fit.calibration.apply(*m));
                prop_assert!((h.norm() - FIELD_UT).abs() < 1e-6 * FIELD_UT, "|h| = {}", h.norm());
            }
            for (got, want) in fit.calibration.hard_iron_ut.iter().zip(hard_iron) {
                prop_assert!((got - want).abs() < 1e-6, "{got} vs {want}");
            }
        }
    }
}
