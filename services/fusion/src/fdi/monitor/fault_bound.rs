//! How far a fault detected and not yet isolated can have moved the fused solution.
//!
//! While the parity test declares a fault it cannot pin on one channel, every candidate stays in
//! the solution. For each candidate i the least-squares estimate of a fault on i alone is its
//! residual `r_i = z_i − h_i·x̂` over `1 − P_ii` (`P = H G` the hat matrix: the share of a fault on
//! i that stays in i's own residual rather than moving the solution), and that fault moves the
//! solution by `G_i f_i` (G's column i). The largest `|G_i f_i|` over the candidates bounds the
//! solution's error from the fault; its square is added to the solution's variance on every axis,
//! so that a consumer (the navigator) sees how far it can be off. With four channels on skewed axes
//! the parity space has one dimension and every channel's fault has the same parity signature:
//! this bound is then all anyone can know until isolation.

use crate::wls::WlsSolver;

/// A channel whose fault hardly reaches its own residual (`1 − P_ii` below this) is not
/// detectable by parity at all; it is not a candidate a declaration can come from.
const MIN_RESIDUAL_SHARE: f64 = 1e-6;

/// The largest solution error a fault on one of `candidates` (bit i = channel i) can cause, given
/// the values `z` the solution `x` was computed from, in the unit of `x`. 0 without candidates.
pub fn solution_error_bound(
    solver: &WlsSolver,
    axes: &[[f64; 3]],
    z: &[f64],
    x: &[f64; 3],
    candidates: u32,
) -> f64 {
    let mut worst = 0.0f64;
    for (i, h) in axes.iter().enumerate() {
        if candidates & (1 << i) == 0 {
            continue;
        }
        let (Some(g), Some(&zi)) = (solver.gain_of(i), z.get(i)) else {
            continue;
        };
        let share = 1.0 - (h[0] * g[0] + h[1] * g[1] + h[2] * g[2]);
        if share.is_nan() || share <= MIN_RESIDUAL_SHARE {
            continue;
        }
        let residual = zi - (h[0] * x[0] + h[1] * x[1] + h[2] * x[2]);
        let fault = residual / share;
        let moved = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt() * fault.abs();
        if moved.is_finite() {
            worst = worst.max(moved);
        }
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Geometry;

    /// Four skewed axes (a regular tetrahedron's), equal noise.
    fn tetrahedron() -> Geometry {
        let s = 1.0 / 3f64.sqrt();
        Geometry::from_axes(&[[s, s, s], [s, -s, -s], [-s, s, -s], [-s, -s, s]]).unwrap()
    }

    #[test]
    fn the_bound_is_the_solution_error_of_the_faulty_candidate() {
        let geometry = tetrahedron();
        let solver = WlsSolver::new(&geometry, 0b1111, &[1e-6; 4]).unwrap();
        let truth = [0.1, -0.2, 0.3];
        let mut z: Vec<f64> = geometry
            .axes()
            .iter()
            .map(|h| h[0] * truth[0] + h[1] * truth[1] + h[2] * truth[2])
            .collect();
        z[2] += 0.02;
        let (x, _) = solver.solve(&z);
        let error =
            ((x[0] - truth[0]).powi(2) + (x[1] - truth[1]).powi(2) + (x[2] - truth[2]).powi(2))
                .sqrt();
        // Three quarters of a 0.02 fault along a unit axis reach the solution.
        assert!((error - 0.015).abs() < 1e-9, "{error}");
        let bound = solution_error_bound(&solver, geometry.axes(), &z, &x, 0b1111);
        // One parity dimension: every candidate explains the residuals with the same fault size,
        // and each moves the solution as far.
        assert!((bound - error).abs() < 1e-9, "{bound} vs {error}");
        assert_eq!(
            solution_error_bound(&solver, geometry.axes(), &z, &x, 0),
            0.0
        );
    }
}
