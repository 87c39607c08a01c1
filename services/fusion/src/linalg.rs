//! Small dense helpers shared by the geometry and the solver.

use nalgebra::{Matrix3, SymmetricEigen, Vector3};

/// Σ w_i h_i h_iᵀ over the given rows: the normal matrix HᵀWH.
pub(crate) fn normal_matrix<'a>(rows: impl Iterator<Item = (&'a [f64; 3], f64)>) -> Matrix3<f64> {
    rows.fold(Matrix3::zeros(), |acc, (h, w)| {
        let v = Vector3::from(*h);
        acc + v * v.transpose() * w
    })
}

/// λ_min / λ_max of a symmetric positive semi-definite matrix; 0 when singular or not finite.
pub(crate) fn reciprocal_condition(m: &Matrix3<f64>) -> f64 {
    if !m.iter().all(|x| x.is_finite()) {
        return 0.0;
    }
    let eig = SymmetricEigen::new(*m).eigenvalues;
    let max = eig.max();
    let min = eig.min();
    if max <= 0.0 {
        0.0
    } else {
        (min / max).max(0.0)
    }
}
