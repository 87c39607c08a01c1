//! Small dense kernels on fixed-size arrays (no allocation), for the parity-space whitening that
//! the adaptive noise estimate refreshes while running.

use super::MAX_PARITY;

/// A symmetric m×m matrix (m ≤ [`MAX_PARITY`]) in the top-left corner of a fixed array.
pub type ParityMatrix = [[f64; MAX_PARITY]; MAX_PARITY];

/// Lower-triangular Cholesky factor L of the top-left m×m block of `a` (a = L Lᵀ), or `None` when
/// that block is not positive definite (or not finite).
pub fn cholesky(a: &ParityMatrix, m: usize) -> Option<ParityMatrix> {
    let mut l = [[0.0; MAX_PARITY]; MAX_PARITY];
    for i in 0..m {
        for j in 0..=i {
            let dot: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
            let s = a[i][j] - dot;
            if i == j {
                if !(s > 0.0 && s.is_finite()) {
                    return None;
                }
                l[i][i] = s.sqrt();
            } else {
                l[i][j] = s / l[j][j];
            }
        }
    }
    Some(l)
}

/// Solves L y = b in place for the lower-triangular m×m factor `l` (forward substitution).
pub fn forward_substitute(l: &ParityMatrix, m: usize, b: &mut [f64; MAX_PARITY]) {
    for i in 0..m {
        let dot: f64 = (0..i).map(|k| l[i][k] * b[k]).sum();
        b[i] = (b[i] - dot) / l[i][i];
    }
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
    }
}
