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
    let cfg: GeometryConfig = toml::from_str(
        "kind = \"axes\"\naxes = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.577, 0.577, 0.577]]",
    )
    .unwrap();
    let g = cfg.build().unwrap();
    // Rounded to three decimals (norm 0.9994), normalised to the exact diagonal.
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
    let d = std::f64::consts::FRAC_1_SQRT_2;
    let e = axes(vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [d, d, 0.0],
        [d, -d, 0.0],
    ]);
    assert!(e.reason.contains("coplanar"), "{e}");
    let e = axes(vec![[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [d, d, 1e-5]]);
    assert!(e.reason.contains("coplanar"), "{e}");
}

#[test]
fn configured_axes_must_be_unit_vectors_within_one_percent() {
    let build = |a: Vec<[f64; 3]>| GeometryConfig::Axes { axes: a }.build();
    let e = build(vec![[5.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]).unwrap_err();
    assert_eq!(
        e.within("fusion.geometry.gyro").to_string(),
        "fusion.geometry.gyro.axes[0] = [5, 0, 0]: must be a unit vector (norm 5)"
    );
    // Just beyond the tolerance on either side, on another axis.
    let e = build(vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0111, 0.0]]).unwrap_err();
    assert_eq!(e.field, "axes[2]");
    assert!(e.reason.contains("norm 1.0111"), "{e}");
    let e = build(vec![[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.989, 0.0]]).unwrap_err();
    assert!(e.reason.contains("norm 0.989"), "{e}");
    // Rounded decimals (norm 0.99995..1.00005) and anything within 1 % are normalised.
    let r = 0.57735;
    let g = build(vec![
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.009],
        [r, r, r],
    ])
    .unwrap();
    for h in g.axes() {
        assert!((dot(*h, *h) - 1.0).abs() < 1e-12, "{h:?}");
    }
    assert!((g.axes()[2][2] - 1.0).abs() < 1e-12);
}

fn stacked(count: usize, rotations_deg: Vec<[f64; 3]>) -> Geometry {
    GeometryConfig::Stacked {
        count,
        rotations_deg,
    }
    .build()
    .unwrap()
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// HᵀH of the geometry, row-major.
fn normal_matrix(g: &Geometry) -> [[f64; 3]; 3] {
    let mut m = [[0.0; 3]; 3];
    for h in g.axes() {
        for r in 0..3 {
            for c in 0..3 {
                m[r][c] += h[r] * h[c];
            }
        }
    }
    m
}

#[test]
fn triad_kind_is_the_body_axes() {
    let g = GeometryConfig::Triad {}.build().unwrap();
    assert_eq!(
        g.axes(),
        &[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
    );
    assert_close(g.variance_factors(), [1.0; 3], 0.0);
    assert_eq!(g.parity_dimension(), 0);
}

#[test]
fn dodecahedron_kind_has_equal_angles_and_isotropic_noise() {
    let g = GeometryConfig::Dodecahedron {}.build().unwrap();
    assert_eq!(g.n(), 6);
    let cos_63 = 1.0 / 5f64.sqrt();
    assert!((cos_63.acos().to_degrees() - 63.43).abs() < 5e-3);
    for (i, a) in g.axes().iter().enumerate() {
        assert!((dot(*a, *a) - 1.0).abs() < 1e-15);
        // Each axis lies in one body coordinate plane.
        assert_eq!(
            a.iter().filter(|c| **c == 0.0).count(),
            1,
            "axis {i}: {a:?}"
        );
        for b in &g.axes()[i + 1..] {
            assert!((dot(*a, *b).abs() - cos_63).abs() < 1e-15, "{a:?} · {b:?}");
        }
    }
    let m = normal_matrix(&g);
    for (r, row) in m.iter().enumerate() {
        for (c, v) in row.iter().enumerate() {
            let expected = if r == c { 2.0 } else { 0.0 };
            assert!((v - expected).abs() < 1e-15, "HᵀH[{r}][{c}] = {v}");
        }
    }
    // 3/N per axis.
    assert_close(g.variance_factors(), [0.5; 3], 1e-15);
    assert_eq!(g.parity_dimension(), 3);
}

#[test]
fn stacked_aligned_triads_repeat_the_body_axes() {
    let g = stacked(4, vec![]);
    assert_eq!(g.n(), 12);
    for (i, h) in g.axes().iter().enumerate() {
        let mut e = [0.0; 3];
        e[i % 3] = 1.0;
        assert_eq!(*h, e, "row {i}");
    }
    // HᵀH = 4I.
    assert_close(g.variance_factors(), [0.25; 3], 1e-15);
    assert_eq!(g.parity_dimension(), 9);
    assert_eq!(g.full_mask(), 0xFFF);
}

#[test]
fn stacked_rotations_are_imu_to_body_zyx_euler_angles() {
    // Yaw 90°: the IMU's forward axis points to the body's right, its right axis to the back.
    let g = stacked(2, vec![[0.0, 0.0, 0.0], [0.0, 0.0, 90.0]]);
    assert_close(g.axes()[3], [0.0, 1.0, 0.0], 1e-15);
    assert_close(g.axes()[4], [-1.0, 0.0, 0.0], 1e-15);
    assert_close(g.axes()[5], [0.0, 0.0, 1.0], 1e-15);
    // Pitch 90° (nose up): the IMU's forward axis points up, i.e. body −z in FRD.
    let g = stacked(1, vec![[0.0, 90.0, 0.0]]);
    assert_close(g.axes()[0], [0.0, 0.0, -1.0], 1e-15);

    let angles = [
        [10.0, -20.0, 30.0],
        [-70.0, 45.0, 170.0],
        [5.0, 80.0, -100.0],
    ];
    let g = stacked(3, angles.to_vec());
    for (k, [r, p, y]) in angles.iter().enumerate() {
        let rot = Rotation3::from_euler_angles(r.to_radians(), p.to_radians(), y.to_radians());
        for (j, e) in [Vector3::x(), Vector3::y(), Vector3::z()]
            .iter()
            .enumerate()
        {
            let v = rot * e;
            assert_close(g.axes()[3 * k + j], [v.x, v.y, v.z], 1e-15);
        }
    }
    // Every triad is orthonormal, so HᵀH = count·I whatever the rotations.
    assert_close(g.variance_factors(), [1.0 / 3.0; 3], 1e-14);
}

#[test]
fn parses_the_new_kinds_from_toml() {
    let parse = |s: &str| toml::from_str::<GeometryConfig>(s).unwrap();
    assert_eq!(parse("kind = \"triad\""), GeometryConfig::Triad {});
    assert_eq!(
        parse("kind = \"dodecahedron\""),
        GeometryConfig::Dodecahedron {}
    );
    assert_eq!(
        parse("kind = \"stacked\"\ncount = 4"),
        GeometryConfig::Stacked {
            count: 4,
            rotations_deg: vec![]
        }
    );
    assert_eq!(
        parse("kind = \"stacked\"\ncount = 2\nrotations_deg = [[0, 0, 0], [180, 0, 45.5]]"),
        GeometryConfig::Stacked {
            count: 2,
            rotations_deg: vec![[0.0; 3], [180.0, 0.0, 45.5]]
        }
    );
    for bad in [
        "kind = \"triad\"\nn = 3",
        "kind = \"dodecahedron\"\nalpha_deg = 30",
        "kind = \"stacked\"\ncount = 2\nrotation_deg = []",
        "kind = \"stacked\"",
    ] {
        assert!(toml::from_str::<GeometryConfig>(bad).is_err(), "{bad}");
    }
}

#[test]
fn stacked_errors_name_field_and_value() {
    let bad = |count, rotations_deg| {
        GeometryConfig::Stacked {
            count,
            rotations_deg,
        }
        .build()
        .unwrap_err()
    };
    assert_eq!(
        bad(0, vec![]).to_string(),
        "count = 0: must be in 1..=5 (3 rows per triad, at most 16 rows)"
    );
    assert_eq!(bad(6, vec![]).field, "count");
    assert_eq!(
        bad(3, vec![[0.0; 3]; 2]).to_string(),
        "rotations_deg = 2 entries: must have 3 entries (one per triad) or be empty"
    );
    let e = bad(2, vec![[0.0; 3], [1.0, f64::INFINITY, 0.0]]);
    assert_eq!(
        e.to_string(),
        "rotations_deg[1] = [1.0, inf, 0.0]: must be finite [roll, pitch, yaw] degrees"
    );
    // The full path through the fusion configuration.
    let cfg: FusionConfig = toml::from_str(
        "[geometry.accel]\nkind = \"stacked\"\ncount = 2\nrotations_deg = [[0, 0, 0]]",
    )
    .unwrap();
    assert_eq!(
        cfg.validate().unwrap_err().field,
        "geometry.accel.rotations_deg"
    );
}
