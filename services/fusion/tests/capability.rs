//! Capability of geometries: noise figures against closed forms, and the detect / isolate /
//! tolerate answers against the generalised likelihood test they stand for.

use proptest::prelude::*;
use rins_fusion::capability::{CAPABILITY_EPSILON, Capability, parity_projector};
use rins_fusion::{Geometry, GeometryConfig};

fn build(c: GeometryConfig) -> Geometry {
    c.build().unwrap()
}

fn cone(n: usize, alpha_deg: f64) -> Geometry {
    build(GeometryConfig::Pyramid {
        n,
        alpha_deg,
        beta0_deg: 0.0,
    })
}

fn stacked(count: usize, rotations_deg: Vec<[f64; 3]>) -> Geometry {
    build(GeometryConfig::Stacked {
        count,
        rotations_deg,
    })
}

/// (detect, isolate_one, tolerate_two)
fn abilities(g: &Geometry) -> (bool, bool, bool) {
    let c = Capability::of(g);
    (c.detect, c.isolate_one, c.tolerate_two)
}

fn assert_close(a: [f64; 3], b: [f64; 3], tol: f64) {
    for k in 0..3 {
        assert!((a[k] - b[k]).abs() <= tol, "axis {k}: {a:?} vs {b:?}");
    }
}

/// Channel picked by the GLT `argmax_j (P z)_j² / P_jj` for a pure fault of size 1 on channel
/// `i` (any motion H x cancels in P z), and whether the maximum is unique.
///
/// The statistic of channel j is `P_ii·cos²θ_ij` (θ_ij: angle between parity columns i and j), so
/// "j ties with i" is "cos²θ_ij ≥ (1 − ε)²": the same structural tolerance ε as
/// [`Capability`]'s parallel-column test, not a tighter one — a pair whose cosine is within ε of 1
/// is indistinguishable by construction, however small the float difference of their statistics.
fn glt_pick(g: &Geometry, i: usize) -> (usize, bool) {
    let p = parity_projector(g.axes()).unwrap();
    let n = g.n();
    let stats: Vec<f64> = (0..n).map(|j| p[j][i] * p[j][i] / p[j][j]).collect();
    let best = (0..n)
        .max_by(|a, b| stats[*a].total_cmp(&stats[*b]))
        .unwrap();
    let ties = stats
        .iter()
        .filter(|s| **s >= stats[best] * (1.0 - CAPABILITY_EPSILON).powi(2))
        .count();
    (best, ties == 1)
}

#[test]
fn seed_pyramid_detects_only() {
    let c = Capability::of(&GeometryConfig::seed_pyramid().build().unwrap());
    assert_eq!(c.n, 4);
    assert_eq!(c.parity_dimension, 1);
    assert_close(c.variance_factors, [0.65, 0.65, 1.084], 2e-3);
    assert_close(
        c.noise_amplification,
        c.variance_factors.map(f64::sqrt),
        1e-15,
    );
    assert!(c.detect && !c.isolate_one && !c.tolerate_two, "{c:?}");
    // One-dimensional parity: every channel's fault looks the same up to sign and size.
    let g = GeometryConfig::seed_pyramid().build().unwrap();
    assert!(!glt_pick(&g, 0).1);
}

#[test]
fn optimal_pyramid_has_three_quarters_per_axis() {
    let c = Capability::of(&cone(4, 35.26));
    assert_close(c.variance_factors, [0.75; 3], 1e-3);
    assert_close(c.noise_amplification, [0.75f64.sqrt(); 3], 1e-3);
    assert_eq!(
        (c.detect, c.isolate_one, c.tolerate_two),
        (true, false, false)
    );
}

#[test]
fn triad_can_do_nothing() {
    let c = Capability::of(&build(GeometryConfig::Triad {}));
    assert_eq!(c.parity_dimension, 0);
    assert_close(c.variance_factors, [1.0; 3], 1e-15);
    assert_eq!(
        (c.detect, c.isolate_one, c.tolerate_two),
        (false, false, false)
    );
}

#[test]
fn dodecahedron_detects_isolates_and_tolerates_two() {
    let g = build(GeometryConfig::Dodecahedron {});
    let c = Capability::of(&g);
    assert_close(c.variance_factors, [0.5; 3], 1e-15);
    assert_eq!(c.parity_dimension, 3);
    assert_eq!(
        (c.detect, c.isolate_one, c.tolerate_two),
        (true, true, true)
    );
    for i in 0..6 {
        assert_eq!(glt_pick(&g, i), (i, true));
    }
}

#[test]
fn five_axis_cone_isolates_one_but_cannot_tolerate_two() {
    let g = cone(5, 30.0);
    let c = Capability::of(&g);
    // Regular cone: HᵀH = diag(N cos²α / 2, N cos²α / 2, N sin²α).
    let a = 30f64.to_radians();
    let xy = 2.0 / (5.0 * a.cos().powi(2));
    assert_close(
        c.variance_factors,
        [xy, xy, 1.0 / (5.0 * a.sin().powi(2))],
        1e-14,
    );
    assert_eq!(
        (c.detect, c.isolate_one, c.tolerate_two),
        (true, true, false)
    );
    for i in 0..5 {
        assert_eq!(glt_pick(&g, i), (i, true));
    }
    // What remains after one exclusion is a 4-channel set: detection only.
    let rest = Capability::of_channels(&g, 0b11110).unwrap();
    assert_eq!(rest.n, 4);
    assert_eq!((rest.detect, rest.isolate_one), (true, false));
}

#[test]
fn aligned_stacked_triads_need_three_copies_to_isolate() {
    // Two aligned triads: each body axis is measured by exactly two rows. A fault on either row
    // of a pair moves the parity vector along the same direction (their difference), so the
    // parity cannot say which of the two failed: P's columns of an aligned pair are parallel.
    let two = stacked(2, vec![]);
    assert_eq!(abilities(&two), (true, false, false));
    let p = parity_projector(two.axes()).unwrap();
    assert!((p[0][3] + p[0][0]).abs() < 1e-15 && (p[0][0] - 0.5).abs() < 1e-15);
    assert!(!glt_pick(&two, 0).1);

    // With k aligned copies each axis is a k-way vote: P restricted to one axis is I − 11ᵀ/k and
    // two copies' columns have cosine −1/(k−1), parallel only for k = 2. So three aligned triads
    // isolate one fault, and four still isolate after losing any one row: the answer is YES for
    // four aligned triads, contrary to the intuition that aligned rows are always parallel.
    let three = stacked(3, vec![]);
    assert_eq!(abilities(&three), (true, true, false));
    let four = stacked(4, vec![]);
    assert_eq!(abilities(&four), (true, true, true));
    let p = parity_projector(four.axes()).unwrap();
    assert!((p[0][0] - 0.75).abs() < 1e-15);
    assert!((p[0][3] + 0.25).abs() < 1e-15);
    // Rows on different body axes do not interact at all.
    assert!(p[0][1].abs() < 1e-15);
    for i in 0..12 {
        assert_eq!(glt_pick(&four, i), (i, true));
    }
}

#[test]
fn rotated_stacked_triads() {
    // Four differently rotated triads: no row is parallel to another, the 9-dimensional parity
    // isolates any single fault and still does after any one exclusion.
    let four = stacked(
        4,
        vec![
            [0.0, 0.0, 0.0],
            [45.0, 0.0, 0.0],
            [0.0, 45.0, 0.0],
            [0.0, 0.0, 45.0],
        ],
    );
    let c = Capability::of(&four);
    assert_close(c.variance_factors, [0.25; 3], 1e-14);
    assert_eq!(
        (c.detect, c.isolate_one, c.tolerate_two),
        (true, true, true)
    );
    for i in 0..12 {
        assert_eq!(glt_pick(&four, i), (i, true));
    }
    // Even two triads become fully capable once rotated against each other (no shared axis).
    let two = stacked(2, vec![[0.0; 3], [30.0, 20.0, 10.0]]);
    assert_eq!(abilities(&two), (true, true, true));
    // But a pure yaw rotation keeps the z axes parallel: that pair stays indistinguishable.
    let two_yawed = stacked(2, vec![[0.0; 3], [0.0, 0.0, 45.0]]);
    assert_eq!(abilities(&two_yawed), (true, false, false));
}

#[test]
fn channel_subsets_and_their_limits() {
    let g = build(GeometryConfig::Dodecahedron {});
    let five = Capability::of_channels(&g, 0b111101).unwrap();
    assert_eq!(five.n, 5);
    assert_eq!(
        (five.detect, five.isolate_one, five.tolerate_two),
        (true, true, false)
    );
    // Bits above N are ignored.
    assert_eq!(
        Capability::of_channels(&g, 0xFFFF_FFFF),
        Some(Capability::of(&g))
    );
    assert_eq!(Capability::of_channels(&g, 0b11), None);
    // Three coplanar axes do not span 3-D.
    let flat = Geometry::from_axes(&[
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0, 0.0],
    ])
    .unwrap();
    assert_eq!(Capability::of_channels(&flat, 0b1011), None);
    // A channel outside every parity relation cannot be detected: the z axis here is measured once.
    let c = Capability::of(&flat);
    assert_eq!((c.n, c.detect), (4, false));
}

#[test]
fn serialises_with_the_documented_field_names() {
    let c = Capability::of(&GeometryConfig::seed_pyramid().build().unwrap());
    let text = toml::to_string(&c).unwrap();
    for key in [
        "n = 4",
        "parity_dimension = 1",
        "detect = true",
        "isolate_one = false",
        "tolerate_two = false",
        "noise_amplification = [",
        "variance_factors = [",
    ] {
        assert!(text.contains(key), "{key} missing from\n{text}");
    }
}

fn unit_axes(n: usize) -> impl Strategy<Value = Vec<[f64; 3]>> {
    prop::collection::vec(
        (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
            .prop_filter("not near zero", |(x, y, z)| x * x + y * y + z * z > 0.01)
            .prop_map(|(x, y, z)| [x, y, z]),
        n,
    )
}

proptest! {
    #[test]
    fn projector_is_the_parity_projection(axes in (4usize..=16).prop_flat_map(unit_axes)) {
        let Ok(g) = Geometry::from_axes(&axes) else { return Ok(()) };
        let n = g.n();
        let p = parity_projector(g.axes()).unwrap();
        let mut trace = 0.0;
        for i in 0..n {
            trace += p[i][i];
            for j in 0..n {
                // Symmetric to the same rounding as the other identities: the projector is built
                // through (HᵀH)⁻¹, whose rounding grows with the geometry's condition number.
                prop_assert!((p[i][j] - p[j][i]).abs() < 1e-9, "P[{i}][{j}] − P[{j}][{i}] = {}", p[i][j] - p[j][i]);
                // Idempotent: P² = P.
                let pp: f64 = (0..n).map(|k| p[i][k] * p[k][j]).sum();
                prop_assert!((pp - p[i][j]).abs() < 1e-9, "P²[{i}][{j}] = {pp} vs {}", p[i][j]);
            }
            // P H = 0: the motion never reaches the parity.
            for c in 0..3 {
                let ph: f64 = (0..n).map(|k| p[i][k] * g.axes()[k][c]).sum();
                prop_assert!(ph.abs() < 1e-9);
            }
        }
        prop_assert!((trace - (n - 3) as f64).abs() < 1e-9);

        let c = Capability::of(&g);
        prop_assert!(!c.isolate_one || c.detect);
        prop_assert!(!c.tolerate_two || c.isolate_one);
        prop_assert_eq!(c.isolate_one, c.detect && n >= 5 && (0..n).all(|i| glt_pick(&g, i) == (i, true)));
    }
}
