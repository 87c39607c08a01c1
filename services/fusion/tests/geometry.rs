//! Geometry: noise figures against closed forms, and validation of bad layouts.

use nalgebra::{Rotation3, Vector3};
use rins_fusion::{FusionConfig, Geometry, GeometryConfig};

fn pyramid(n: usize, alpha_deg: f64, beta0_deg: f64) -> Geometry {
    GeometryConfig::Pyramid {
        n,
        alpha_deg,
        beta0_deg,
    }
    .build()
    .unwrap()
}

fn assert_close(a: [f64; 3], b: [f64; 3], tol: f64) {
    for k in 0..3 {
        assert!((a[k] - b[k]).abs() <= tol, "axis {k}: {a:?} vs {b:?}");
    }
}

#[test]
fn seed_pyramid_variance_factors_match_closed_form() {
    // β0 = 45°, n = 4: HᵀH = diag(2cos²α, 2cos²α, 4sin²α).
    let alpha = 28.7_f64.to_radians();
    let g = pyramid(4, 28.7, 45.0);
    let xy = 1.0 / (2.0 * alpha.cos().powi(2));
    let z = 1.0 / (4.0 * alpha.sin().powi(2));
    assert_close(g.variance_factors(), [xy, xy, z], 1e-12);
    // The figures quoted in the design.
    assert_close(g.variance_factors(), [0.65, 0.65, 1.084], 2e-3);
    assert_close(
        g.noise_amplification(),
        [xy.sqrt(), xy.sqrt(), z.sqrt()],
        1e-12,
    );
    assert_eq!(g.parity_dimension(), 1);
    assert_eq!(g.n(), 4);
}

#[test]
fn seed_pyramid_axes_follow_the_formula() {
    let g = pyramid(4, 28.7, 45.0);
    let (sa, ca) = 28.7_f64.to_radians().sin_cos();
    for (i, h) in g.axes().iter().enumerate() {
        let beta = (45.0 + 90.0 * i as f64).to_radians();
        assert_close(*h, [ca * beta.cos(), ca * beta.sin(), sa], 1e-12);
    }
}

#[test]
fn optimal_pyramid_is_isotropic() {
    let g = pyramid(4, 35.26, 45.0);
    assert_close(g.variance_factors(), [0.75, 0.75, 0.75], 1e-3);
    // Exactly isotropic at α = atan(1/√2).
    let exact = pyramid(4, (1.0 / 2f64.sqrt()).atan().to_degrees(), 0.0);
    assert_close(exact.variance_factors(), [0.75; 3], 1e-12);
    assert!((exact.reciprocal_condition() - 1.0).abs() < 1e-9);
}

#[test]
fn orthogonal_triad_has_unit_factors_and_no_parity() {
    let g = Geometry::from_axes(&[[2.0, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, -3.0]]).unwrap();
    assert_close(g.variance_factors(), [1.0; 3], 1e-12);
    assert_close(g.noise_amplification(), [1.0; 3], 1e-12);
    assert_eq!(g.parity_dimension(), 0);
    // Axes are normalised.
    assert_close(g.axes()[2], [0.0, 0.0, -1.0], 0.0);
}

#[test]
fn six_axis_dodecahedron_and_stacked_triads() {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let dodeca = [
        [0.0, 1.0, phi],
        [0.0, -1.0, phi],
        [1.0, phi, 0.0],
        [-1.0, phi, 0.0],
        [phi, 0.0, 1.0],
        [phi, 0.0, -1.0],
    ];
    let g = Geometry::from_axes(&dodeca).unwrap();
    // HᵀH = (N/3) I.
    assert_close(g.variance_factors(), [0.5; 3], 1e-12);
    assert_eq!(g.parity_dimension(), 3);

    let mut stacked = Vec::new();
    for (r, p, y) in [
        (0.0, 0.0, 0.0),
        (0.3, -0.2, 1.0),
        (1.1, 0.4, -2.0),
        (-0.7, 1.2, 0.5),
    ] {
        let rot = Rotation3::from_euler_angles(r, p, y);
        for e in [Vector3::x(), Vector3::y(), Vector3::z()] {
            let v = rot * e;
            stacked.push([v.x, v.y, v.z]);
        }
    }
    let g = Geometry::from_axes(&stacked).unwrap();
    assert_eq!(g.n(), 12);
    assert_close(g.variance_factors(), [0.25; 3], 1e-12);
}

#[test]
fn parses_both_kinds_from_toml() {
    let cfg: GeometryConfig =
        toml::from_str("kind = \"pyramid\"\nn = 4\nalpha_deg = 28.7\nbeta0_deg = 45.0").unwrap();
    assert_eq!(cfg, GeometryConfig::seed_pyramid());
    assert_eq!(cfg, GeometryConfig::default());
    let cfg: GeometryConfig =
        toml::from_str("kind = \"axes\"\naxes = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1]]")
            .unwrap();
    let g = cfg.build().unwrap();
    let s = 1.0 / 3f64.sqrt();
    assert_close(g.axes()[3], [s, s, s], 1e-15);
}

#[test]
fn rejects_unknown_fields_and_kinds() {
    let unknown_field =
        "kind = \"pyramid\"\nn = 4\nalpha_deg = 28.7\nbeta0_deg = 45.0\ngamma_deg = 1.0";
    let e = toml::from_str::<GeometryConfig>(unknown_field).unwrap_err();
    assert!(e.to_string().contains("unknown field `gamma_deg`"), "{e}");
    assert!(toml::from_str::<GeometryConfig>("kind = \"cube\"\nn = 4").is_err());
    assert!(
        toml::from_str::<GeometryConfig>("kind = \"axes\"\naxes = [[1, 0, 0]]\nn = 3").is_err()
    );
}

#[test]
fn errors_name_field_and_value() {
    let cfg: FusionConfig = toml::from_str(
        "[geometry.gyro]\nkind = \"pyramid\"\nn = 4\nalpha_deg = 95\nbeta0_deg = 45",
    )
    .unwrap();
    assert_eq!(
        cfg.validate().unwrap_err().to_string(),
        "geometry.gyro.alpha_deg = 95: must be in (-90, 90)"
    );

    let bad = |c: GeometryConfig| c.build().unwrap_err();
    let e = bad(GeometryConfig::Pyramid {
        n: 2,
        alpha_deg: 30.0,
        beta0_deg: 0.0,
    });
    assert_eq!(e.to_string(), "n = 2: must be in 3..=16");
    let e = bad(GeometryConfig::Pyramid {
        n: 17,
        alpha_deg: 30.0,
        beta0_deg: 0.0,
    });
    assert_eq!(e.field, "n");
    let e = bad(GeometryConfig::Pyramid {
        n: 4,
        alpha_deg: f64::NAN,
        beta0_deg: 0.0,
    });
    assert_eq!(e.field, "alpha_deg");
    // A flat pyramid spans only the x-y plane.
    let e = bad(GeometryConfig::Pyramid {
        n: 4,
        alpha_deg: 0.0,
        beta0_deg: 0.0,
    });
    assert_eq!(e.field, "alpha_deg");
    assert!(e.reason.contains("coplanar"), "{e}");

    let axes = |a: Vec<[f64; 3]>| bad(GeometryConfig::Axes { axes: a });
    let e = axes(vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
    assert_eq!(e.to_string(), "axes = 2 axes: must have 3..=16 axes");
    assert_eq!(axes(vec![[1.0, 0.0, 0.0]; 17]).field, "axes");
    let e = axes(vec![[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
    assert_eq!(
        e.to_string(),
        "axes[1] = [0.0, 0.0, 0.0]: must be a finite non-zero vector"
    );
    let e = axes(vec![[1.0, 0.0, 0.0], [0.0, f64::NAN, 0.0], [0.0, 0.0, 1.0]]);
    assert_eq!(e.field, "axes[1]");
    // Exactly and nearly coplanar (cond(H) far above 1000).
    let e = axes(vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
    ]);
    assert!(e.reason.contains("coplanar"), "{e}");
    let e = axes(vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 1e-5]]);
    assert!(e.reason.contains("coplanar"), "{e}");
}
