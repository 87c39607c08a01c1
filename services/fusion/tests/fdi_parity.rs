//! χ² quantiles against tables and closed forms; parity basis properties; the test statistic and
//! the GLT against their closed forms.

mod common;

use common::{dodecahedron, pyramid4, stacked_two};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::fdi::MAX_PARITY;
use rins_fusion::fdi::chi2::{chi2_survival, chi2_upper_quantile};
use rins_fusion::geometry::MAX_CHANNELS;
use rins_fusion::{Geometry, GeometryConfig, ParitySpace, WlsSolver};

/// Upper quantiles of χ²(dof) at tail probability α (published tables; the 1e-7 rows and the
/// two-dof row from the closed forms erfc(√(x/2)) and e^{-x/2}).
const TABLE: [(usize, f64, f64); 12] = [
    (1, 0.05, 3.841_458_820_694_124),
    (1, 0.01, 6.634_896_601_021_214),
    (1, 1e-7, 28.373_987_361_779_15),
    (2, 1e-7, 32.236_191_301_916_64),
    (3, 0.05, 7.814_727_903_251_178),
    (3, 0.001, 16.266_236_196_238_13),
    (3, 1e-7, 35.405_751_579_937_26),
    (5, 1e-12, 65.238_636_213_367_84),
    (7, 0.5, 6.345_811_195_521_516),
    (10, 0.05, 18.307_038_053_275_146),
    (13, 0.001, 34.528_178_974_870_88),
    (13, 1e-7, 58.432_423_188_319_135),
];

#[test]
fn chi2_quantile_matches_tables() {
    for (dof, alpha, x) in TABLE {
        let q = chi2_upper_quantile(dof, alpha).unwrap();
        assert!((q - x).abs() < 1e-9 * x, "χ²({dof}) at {alpha}: {q} vs {x}");
    }
}

/// Even dof: P(X > x) = e^{-x/2} Σ_{j<k} (x/2)^j / j!, k = dof/2.
fn even_dof_survival(x: f64, dof: usize) -> f64 {
    let y = x / 2.0;
    let mut term = 1.0;
    let mut sum = 0.0;
    for j in 0..dof / 2 {
        sum += term;
        term *= y / (j + 1) as f64;
    }
    (-y).exp() * sum
}

proptest! {
    #[test]
    fn survival_matches_even_closed_form_and_inverts(k in 1usize..=7, x in 0.01..120.0f64, log_alpha in -14.0..-0.5f64) {
        let dof = 2 * k;
        let exact = even_dof_survival(x, dof);
        let s = chi2_survival(x, dof);
        prop_assert!((s - exact).abs() <= 1e-12 * exact.max(1e-300) + 1e-300, "{s} vs {exact}");
        let alpha = 10f64.powf(log_alpha);
        for d in [dof - 1, dof] {
            let q = chi2_upper_quantile(d, alpha).unwrap();
            let back = chi2_survival(q, d);
            prop_assert!((back / alpha - 1.0).abs() < 1e-9, "dof {d}: {back} vs {alpha}");
        }
    }
}

fn check_basis(g: &Geometry, mask: u32) -> ParitySpace {
    let var = vec![1.0; g.n()];
    let space = ParitySpace::new(g, mask, &var).unwrap();
    let v = space.basis();
    let m = space.dimension();
    assert_eq!(m, (mask & g.full_mask()).count_ones() as usize - 3);
    for a in 0..m {
        // V H = 0.
        for k in 0..3 {
            let vh: f64 = (0..g.n()).map(|i| v[a][i] * g.axes()[i][k]).sum();
            assert!(vh.abs() < 1e-12, "(VH)[{a}][{k}] = {vh}");
        }
        // V Vᵀ = I.
        for b in 0..m {
            let vv: f64 = (0..g.n()).map(|i| v[a][i] * v[b][i]).sum();
            let want = if a == b { 1.0 } else { 0.0 };
            assert!((vv - want).abs() < 1e-12);
        }
        // Inactive channels carry no weight.
        for i in (0..g.n()).filter(|i| mask & (1 << i) == 0) {
            assert_eq!(v[a][i], 0.0);
        }
    }
    space
}

#[test]
fn basis_is_an_orthonormal_left_null_space() {
    check_basis(&pyramid4(), 0b1111);
    check_basis(&dodecahedron(), 0b11_1111);
    check_basis(&dodecahedron(), 0b11_0111);
    check_basis(&stacked_two(), 0b11_1111);
    let triad = GeometryConfig::Triad {}.build().unwrap();
    assert_eq!(check_basis(&triad, 0b111).dimension(), 0);
}

/// Random unit axes, rejected unless well conditioned.
fn random_geometry() -> impl Strategy<Value = Geometry> {
    prop::collection::vec(prop::array::uniform3(-1.0..1.0f64), 4..=16).prop_filter_map(
        "ill-conditioned",
        |axes| {
            let axes: Vec<[f64; 3]> = axes
                .into_iter()
                .filter(|a| a.iter().map(|c| c * c).sum::<f64>() > 0.01)
                .collect();
            Geometry::from_axes(&axes)
                .ok()
                .filter(|g| g.n() >= 4 && g.reciprocal_condition() > 1e-2)
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// T = pᵀ(V R Vᵀ)⁻¹p equals the weighted least-squares residual Σ r_i²/σ_i², is independent of
    /// the motion, and a bias on channel i makes channel i the GLT winner.
    #[test]
    fn statistic_is_the_weighted_residual_and_glt_finds_the_biased_channel(
        g in random_geometry(),
        x in prop::array::uniform3(-50.0..50.0f64),
        sigmas in prop::collection::vec(0.01..1.0f64, 16),
        noise in prop::collection::vec(-1.0..1.0f64, 16),
        faulty in 0usize..16,
    ) {
        let n = g.n();
        let var: Vec<f64> = sigmas[..n].iter().map(|s| s * s).collect();
        let space = ParitySpace::new(&g, g.full_mask(), &var).unwrap();
        let solver = WlsSolver::new(&g, g.full_mask(), &var).unwrap();
        let clean = |i: usize| {
            let h = g.axes()[i];
            h[0] * x[0] + h[1] * x[1] + h[2] * x[2]
        };
        let z: [f64; MAX_CHANNELS] =
            std::array::from_fn(|i| if i < n { clean(i) + sigmas[i] * noise[i] } else { 0.0 });
        let mut pw = [0.0; MAX_PARITY];
        let t = space.whitened_parity(&z, &mut pw);
        let (xh, _) = solver.solve(&z);
        let residual: f64 = (0..n).map(|i| {
            let h = g.axes()[i];
            let r = z[i] - (h[0] * xh[0] + h[1] * xh[1] + h[2] * xh[2]);
            r * r / var[i]
        }).sum();
        prop_assert!((t - residual).abs() <= 1e-7 * (1.0 + residual), "T {t} vs residual {residual}");

        // Pure fault, no noise, no motion dependence: the GLT picks a twin of the faulty channel.
        let faulty = faulty % n;
        let mut zf: [f64; MAX_CHANNELS] = std::array::from_fn(|i| if i < n { clean(i) } else { 0.0 });
        let t0 = space.whitened_parity(&zf, &mut pw);
        prop_assert!(t0 < 1e-12 * (1.0 + x.iter().map(|c| c * c).sum::<f64>()) / var.iter().cloned().fold(f64::INFINITY, f64::min));
        zf[faulty] += 10.0 * sigmas[faulty];
        space.whitened_parity(&zf, &mut pw);
        let mut scores = [0.0; MAX_CHANNELS];
        if space.twins(faulty) != 0 {
            let best = space.glt_scores(&pw, &mut scores).unwrap();
            prop_assert!(space.twins(faulty) & (1 << best) != 0, "best {best}, faulty {faulty}");
        }
    }
}

/// Fault-free T is χ²(m): mean m, variance 2m, with unequal channel noise.
#[test]
fn fault_free_statistic_is_chi_squared() {
    let g = dodecahedron();
    let sigmas = [0.01, 0.02, 0.015, 0.03, 0.01, 0.025];
    let var = sigmas.map(|s| s * s);
    let space = ParitySpace::new(&g, g.full_mask(), &var).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    const M: usize = 200_000;
    let (mut sum, mut sum2) = (0.0, 0.0);
    let mut pw = [0.0; MAX_PARITY];
    for _ in 0..M {
        let mut z = [0.0; MAX_CHANNELS];
        for ((zi, h), s) in z.iter_mut().zip(g.axes()).zip(sigmas) {
            let e: f64 = StandardNormal.sample(&mut rng);
            *zi = 3.0 * h[2] + s * e;
        }
        let t = space.whitened_parity(&z, &mut pw);
        sum += t;
        sum2 += t * t;
    }
    let m = 3.0;
    let mean = sum / M as f64;
    let var_t = sum2 / M as f64 - mean * mean;
    // Standard errors: of the mean √(2m/M); of the sample variance, relative, √((8m² + 48m)/M)/(2m)
    // = 0.55 % here (χ²(m) has fourth central moment 12m(m + 4)). 3 % is 5.5 of those.
    assert!(
        (mean - m).abs() < 5.0 * (2.0 * m / M as f64).sqrt(),
        "mean {mean}"
    );
    assert!((var_t / (2.0 * m) - 1.0).abs() < 0.03, "variance {var_t}");
}

#[test]
fn twins_mark_what_parity_cannot_tell_apart() {
    // N = 4: one parity dimension, every channel a twin of every other.
    let p4 = ParitySpace::new(&pyramid4(), 0b1111, &[1.0; 4]).unwrap();
    for i in 0..4 {
        assert_eq!(p4.twins(i), 0b1111);
    }
    // Dodecahedron: no two columns parallel.
    let p6 = ParitySpace::new(&dodecahedron(), 0b11_1111, &[1.0; 6]).unwrap();
    for i in 0..6 {
        assert_eq!(p6.twins(i), 1 << i);
    }
    // Two aligned triads: channel k and k + 3 measure the same axis.
    let aligned = GeometryConfig::Stacked {
        count: 2,
        rotations_deg: vec![],
    }
    .build()
    .unwrap();
    let pa = ParitySpace::new(&aligned, 0b11_1111, &[1.0; 6]).unwrap();
    for k in 0..3 {
        assert_eq!(pa.twins(k), (1 << k) | (1 << (k + 3)));
    }
    // A triad plus a fourth axis along x: y and z are invisible to parity.
    let g = Geometry::from_axes(&[
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.0],
    ])
    .unwrap();
    let p = ParitySpace::new(&g, 0b1111, &[1.0; 4]).unwrap();
    assert_eq!(p.detectable_mask(), 0b1001);
    assert_eq!((p.twins(1), p.twins(2)), (0, 0));
}
