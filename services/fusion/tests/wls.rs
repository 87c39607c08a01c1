//! Weighted least squares: exact recovery, reduced channel sets, noise covariance.

use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::{Geometry, GeometryConfig, WlsError, WlsSolver};

fn seed_pyramid() -> Geometry {
    GeometryConfig::seed_pyramid().build().unwrap()
}

fn measure(g: &Geometry, x: [f64; 3]) -> Vec<f64> {
    g.axes()
        .iter()
        .map(|h| h[0] * x[0] + h[1] * x[1] + h[2] * x[2])
        .collect()
}

fn assert_recovers(solver: &WlsSolver, z: &[f64], x: [f64; 3], tol: f64) {
    let (xh, _) = solver.solve(z);
    for k in 0..3 {
        assert!((xh[k] - x[k]).abs() <= tol, "axis {k}: {xh:?} vs {x:?}");
    }
}

#[test]
fn recovers_exactly_with_all_channels_and_every_three_channel_subset() {
    let g = seed_pyramid();
    let x = [0.3, -1.7, 2.2];
    let mut z = measure(&g, x);
    let var = [1.0; 4];
    assert_recovers(&WlsSolver::new(&g, 0b1111, &var).unwrap(), &z, x, 1e-12);
    for dropped in 0..4 {
        let mask = 0b1111 & !(1 << dropped);
        // The dropped channel holds garbage: it must never be read.
        z[dropped] = f64::NAN;
        let solver = WlsSolver::new(&g, mask, &var).unwrap();
        assert_eq!(solver.active_count(), 3);
        assert_eq!(solver.mask(), mask);
        assert_recovers(&solver, &z, x, 1e-12);
        z = measure(&g, x);
    }
}

#[test]
fn equal_noise_covariance_is_sigma_squared_times_geometry_factors() {
    let g = seed_pyramid();
    let sigma2 = 0.004;
    let solver = WlsSolver::new(&g, u32::MAX, &[sigma2; 4]).unwrap();
    assert_eq!(solver.mask(), 0b1111, "bits above N are ignored");
    let (_, var) = solver.solve(&[0.0; 4]);
    for (v, f) in var.iter().zip(g.variance_factors()) {
        assert!((v - sigma2 * f).abs() < 1e-15);
    }
    // β0 = 45° makes HᵀH diagonal.
    let c = solver.covariance();
    assert!(c[0][1].abs() < 1e-15 && c[0][2].abs() < 1e-15 && c[1][2].abs() < 1e-15);
}

#[test]
fn rejects_too_few_rank_deficient_and_bad_variances() {
    let g = seed_pyramid();
    assert_eq!(
        WlsSolver::new(&g, 0b0101, &[1.0; 4]),
        Err(WlsError::InsufficientChannels {
            mask: 0b0101,
            active: 2
        })
    );
    let coplanar = Geometry::from_axes(&[
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ])
    .unwrap();
    assert!(WlsSolver::new(&coplanar, 0b1111, &[1.0; 4]).is_ok());
    assert!(matches!(
        WlsSolver::new(&coplanar, 0b0111, &[1.0; 4]),
        Err(WlsError::RankDeficient { mask: 0b0111, .. })
    ));
    assert_eq!(
        WlsSolver::new(&g, 0b1111, &[1.0, 0.0, 1.0, 1.0]),
        Err(WlsError::InvalidVariance {
            channel: 1,
            value: 0.0
        })
    );
    assert_eq!(
        WlsSolver::new(&g, 0b1111, &[1.0; 3]),
        Err(WlsError::VarianceCount {
            expected: 4,
            given: 3
        })
    );
}

/// Empirical covariance of x̂ over many noisy samples against (HᵀWH)⁻¹, with unequal channel noise.
#[test]
fn empirical_covariance_matches_prediction() {
    let g = seed_pyramid();
    let sigmas = [0.01, 0.02, 0.015, 0.03];
    let var = sigmas.map(|s| s * s);
    for mask in [0b1111, 0b1011] {
        let solver = WlsSolver::new(&g, mask, &var).unwrap();
        let predicted = solver.covariance();
        let x = [0.5, -0.2, 9.0];
        let clean = measure(&g, x);
        let mut rng = ChaCha8Rng::seed_from_u64(7 + u64::from(mask));
        const M: usize = 40_000;
        let mut sum = [0.0; 3];
        let mut sum2 = [[0.0; 3]; 3];
        for _ in 0..M {
            let z: Vec<f64> = clean
                .iter()
                .zip(&sigmas)
                .map(|(c, s)| {
                    let n: f64 = StandardNormal.sample(&mut rng);
                    c + s * n
                })
                .collect::<Vec<f64>>();
            let (xh, _) = solver.solve(&z);
            let e = [xh[0] - x[0], xh[1] - x[1], xh[2] - x[2]];
            for a in 0..3 {
                sum[a] += e[a];
                for b in 0..3 {
                    sum2[a][b] += e[a] * e[b];
                }
            }
        }
        let m = M as f64;
        for a in 0..3 {
            // Unbiased: the mean error is within 5 standard errors of zero.
            let se = (predicted[a][a] / m).sqrt();
            assert!((sum[a] / m).abs() < 5.0 * se, "bias on axis {a}");
            for b in 0..3 {
                let cov = sum2[a][b] / m;
                // Standard error of a sample (co)variance of Gaussians: sqrt((c_aa c_bb + c_ab²)/M).
                let se = ((predicted[a][a] * predicted[b][b] + predicted[a][b].powi(2)) / m).sqrt();
                assert!(
                    (cov - predicted[a][b]).abs() < 5.0 * se,
                    "mask {mask:#b} cov[{a}][{b}] = {cov:e}, predicted {:e}",
                    predicted[a][b]
                );
            }
        }
    }
}

/// Random unit axes; rejected by `Geometry::from_axes` unless well conditioned.
fn random_geometry() -> impl Strategy<Value = Geometry> {
    prop::collection::vec(prop::array::uniform3(-1.0..1.0f64), 3..=16).prop_filter_map(
        "ill-conditioned",
        |axes| {
            let axes: Vec<[f64; 3]> = axes
                .into_iter()
                .filter(|a| a.iter().map(|c| c * c).sum::<f64>() > 0.01)
                .collect();
            Geometry::from_axes(&axes)
                .ok()
                .filter(|g| g.reciprocal_condition() > 1e-2)
        },
    )
}

proptest! {
    #[test]
    fn random_geometry_recovers_random_vector(
        g in random_geometry(),
        x in prop::array::uniform3(-100.0..100.0f64),
        sigmas in prop::collection::vec(0.001..1.0f64, 16),
    ) {
        let var: Vec<f64> = sigmas[..g.n()].iter().map(|s| s * s).collect();
        let solver = WlsSolver::new(&g, g.full_mask(), &var).unwrap();
        let (xh, v) = solver.solve(&measure(&g, x));
        let min_var = var.iter().copied().fold(f64::INFINITY, f64::min);
        let max_var = var.iter().copied().fold(0.0, f64::max);
        // Rounding error of a least-squares solution: a few thousand ulps of the largest component,
        // amplified by the condition number of the weighted geometry, which is at most the
        // geometry's times the ratio of the largest to the smallest σ.
        let x_max = x.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        let tolerance =
            1e-12 * (1.0 + x_max) * (max_var / min_var).sqrt() / g.reciprocal_condition();
        for k in 0..3 {
            prop_assert!((xh[k] - x[k]).abs() <= tolerance, "{:?} vs {:?}", xh, x);
            prop_assert!(v[k] > 0.0 && v[k].is_finite());
        }
        // min σ² · HᵀH⁻¹ ≤ (HᵀWH)⁻¹ ≤ max σ² · HᵀH⁻¹ in the Loewner order, so on the diagonal too.
        for (vk, f) in v.iter().zip(g.variance_factors()) {
            prop_assert!(*vk <= f * max_var * (1.0 + 1e-9) && *vk >= f * min_var * (1.0 - 1e-9));
        }
    }
}
