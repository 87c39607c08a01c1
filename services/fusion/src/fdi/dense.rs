//! Small dense kernels on fixed-size arrays (no allocation), for the parity-space whitening that
//! the adaptive noise estimate refreshes while running. The factorisation and the triangular solve
//! are nalgebra's, on stack matrices of the largest parity dimension.

use nalgebra::{Cholesky, SMatrix};

use super::MAX_PARITY;

/// A symmetric m×m matrix (m ≤ [`MAX_PARITY`]) in the top-left corner of a fixed array.
pub type ParityMatrix = [[f64; MAX_PARITY]; MAX_PARITY];

/// The largest parity matrix as a nalgebra stack matrix.
type Square = SMatrix<f64, MAX_PARITY, MAX_PARITY>;

/// Lower-triangular Cholesky factor L of the top-left m×m block of `a` (a = L Lᵀ), zero outside
/// that block, or `None` when the block is not positive definite (or not finite).
pub fn cholesky(a: &ParityMatrix, m: usize) -> Option<ParityMatrix> {
    let m = m.min(MAX_PARITY);
    // The unused corner is the identity, so the fixed-size matrix is positive definite exactly when
    // its m×m block is, and its factor is the block's factor beside the identity.
    let padded = Square::from_fn(|r, c| match (r < m && c < m, r == c) {
        (true, _) => a[r][c],
        (false, true) => 1.0,
        (false, false) => 0.0,
    });
    if padded.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let l = Cholesky::new(padded)?.unpack();
    // nalgebra refuses a zero or negative pivot; a pivot that overflowed is refused here.
    if (0..m).any(|i| !l[(i, i)].is_finite()) {
        return None;
    }
    Some(std::array::from_fn(|r| {
        std::array::from_fn(|c| if r < m && c < m { l[(r, c)] } else { 0.0 })
    }))
}

/// Solves L y = b in place for the lower-triangular m×m factor `l` from [`cholesky`] (forward
/// substitution); entries of `b` past m are left as they are.
pub fn forward_substitute(l: &ParityMatrix, m: usize, b: &mut [f64; MAX_PARITY]) {
    let m = m.min(MAX_PARITY);
    let l = Square::from_fn(|r, c| l[r][c]);
    let mut y = nalgebra::SVector::<f64, MAX_PARITY>::from_column_slice(b);
    // A factor from `cholesky` has a positive diagonal, so the solve cannot meet a zero pivot.
    let _solved = l
        .view((0, 0), (m, m))
        .solve_lower_triangular_mut(&mut y.rows_mut(0, m));
    b[..m].copy_from_slice(&y.as_slice()[..m]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn factor_reproduces_the_matrix_and_solves() {
        let mut a = [[0.0; MAX_PARITY]; MAX_PARITY];
        let m = 3;
        let rows = [[4.0, 2.0, 0.4], [2.0, 5.0, 1.0], [0.4, 1.0, 3.0]];
        for i in 0..m {
            a[i][..m].copy_from_slice(&rows[i]);
        }
        let l = cholesky(&a, m).unwrap();
        for i in 0..m {
            for j in 0..m {
                let llt: f64 = (0..m).map(|k| l[i][k] * l[j][k]).sum();
                assert!((llt - a[i][j]).abs() < 1e-12);
            }
        }
        let mut b = [0.0; MAX_PARITY];
        b[..3].copy_from_slice(&[1.0, -2.0, 0.5]);
        let orig = b;
        forward_substitute(&l, m, &mut b);
        for i in 0..m {
            let lb: f64 = (0..m).map(|k| l[i][k] * b[k]).sum();
            assert!((lb - orig[i]).abs() < 1e-12);
        }
        a[2][2] = -1.0;
        assert!(cholesky(&a, m).is_none());
        a[2][2] = f64::NAN;
        assert!(cholesky(&a, m).is_none());
        a[2][2] = f64::INFINITY;
        assert!(cholesky(&a, m).is_none());
    }

    /// The textbook row-by-row factorisation and substitution, the reference for nalgebra's.
    fn reference_factor_and_solve(
        a: &ParityMatrix,
        m: usize,
        b: &mut [f64; MAX_PARITY],
    ) -> ParityMatrix {
        let mut l = [[0.0; MAX_PARITY]; MAX_PARITY];
        for i in 0..m {
            for j in 0..=i {
                let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
                l[i][j] = if i == j { s.sqrt() } else { s / l[j][j] };
            }
        }
        for i in 0..m {
            b[i] = (b[i] - (0..i).map(|k| l[i][k] * b[k]).sum::<f64>()) / l[i][i];
        }
        l
    }

    proptest::proptest! {
        /// On random covariances of every parity dimension, nalgebra's factor and solve agree with
        /// the textbook ones to rounding.
        #[test]
        fn agrees_with_the_textbook_factorisation(
            m in 1usize..=MAX_PARITY,
            entries in proptest::collection::vec(-1.0f64..1.0, MAX_PARITY * MAX_PARITY),
            rhs in proptest::collection::vec(-10.0f64..10.0, MAX_PARITY),
        ) {
            // A = G Gᵀ + 0.1 I: symmetric positive definite with a bounded condition number.
            let mut a = [[0.0; MAX_PARITY]; MAX_PARITY];
            for i in 0..m {
                for j in 0..m {
                    a[i][j] = (0..m).map(|k| entries[i * MAX_PARITY + k] * entries[j * MAX_PARITY + k]).sum::<f64>()
                        + if i == j { 0.1 } else { 0.0 };
                }
            }
            let mut b: [f64; MAX_PARITY] = std::array::from_fn(|i| rhs[i]);
            let mut reference_b = b;
            let reference = reference_factor_and_solve(&a, m, &mut reference_b);
            let l = cholesky(&a, m).unwrap();
            forward_substitute(&l, m, &mut b);
            for i in 0..MAX_PARITY {
                for j in 0..MAX_PARITY {
                    proptest::prop_assert!((l[i][j] - reference[i][j]).abs() < 1e-12, "L[{i}][{j}]");
                }
                proptest::prop_assert!((b[i] - reference_b[i]).abs() < 1e-9, "y[{i}]: {} vs {}", b[i], reference_b[i]);
            }
        }
    }
}
