//! ImuFuser: counts in, body rate and specific force out, honouring the valid mask.

use rins_fusion::fuser::{default_accel_sigma_mps2, default_gyro_sigma_rps};
use rins_fusion::{
    ChannelCalibration, ChannelNoise, FusionConfig, Geometry, GeometryConfig, ImuFuser, WlsSolver,
};

const GYRO_LSB: f64 = 0.0017; // ≈ ±200 °/s over 12 bits
const ACCEL_LSB: f64 = 0.0479; // ≈ ±10 g over 12 bits
const ALL_VALID: u32 = 0x000F_000F;

/// Counts a channel with this calibration reports for the true axis component `m`.
fn to_counts(m: f64, lsb: f64, bias: f64, scale: f64) -> i16 {
    ((m * scale + bias) / lsb).round() as i16
}

fn counts_for(g: &Geometry, x: [f64; 3], lsb: f64, cal: &ChannelCalibration) -> Vec<i16> {
    g.axes()
        .iter()
        .enumerate()
        .map(|(i, h)| {
            let m = h[0] * x[0] + h[1] * x[1] + h[2] * x[2];
            let bias = cal.bias.get(i).copied().unwrap_or(0.0);
            let scale = cal.scale.get(i).copied().unwrap_or(1.0);
            to_counts(m, lsb, bias, scale)
        })
        .collect()
}

/// Worst-case error from rounding to counts: |Σ_i G_ki e_i| ≤ ‖G_k‖·‖e‖ with ‖G_k‖² = (HᵀH)⁻¹_kk
/// (equal weights) and |e_i| ≤ lsb/(2·scale_i).
fn rounding_bound(g: &Geometry, lsb: f64, min_scale: f64) -> [f64; 3] {
    let e = (g.n() as f64).sqrt() * lsb / (2.0 * min_scale);
    g.noise_amplification().map(|a| a * e)
}

fn assert_within(a: [f64; 3], b: [f64; 3], tol: [f64; 3]) {
    for k in 0..3 {
        assert!(
            (a[k] - b[k]).abs() <= tol[k],
            "axis {k}: {a:?} vs {b:?} (tol {tol:?})"
        );
    }
}

#[test]
fn default_config_fuses_the_seed_pyramid() {
    let cfg = FusionConfig::default();
    cfg.validate().unwrap();
    let mut fuser = ImuFuser::new(&cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    let g = *fuser.gyro_geometry();
    assert_eq!(g, GeometryConfig::seed_pyramid().build().unwrap());
    let rate = [0.4, -0.25, 1.1];
    let force = [1.0, -2.0, -9.80665];
    let cal = ChannelCalibration::default();
    let gc = counts_for(&g, rate, GYRO_LSB, &cal);
    let ac = counts_for(fuser.accel_geometry(), force, ACCEL_LSB, &cal);
    let f = fuser.fuse(&gc, &ac, ALL_VALID);
    assert!(f.gyro_ok && f.accel_ok);
    assert_eq!((f.gyro_mask, f.accel_mask), (0b1111, 0b1111));
    assert_within(f.rate, rate, rounding_bound(&g, GYRO_LSB, 1.0));
    assert_within(f.specific_force, force, rounding_bound(&g, ACCEL_LSB, 1.0));
    // Default noise: 0.01 °/s/√Hz and 150 µg/√Hz at 1 kHz, amplified by the seed geometry.
    let sg = 0.01_f64.to_radians() * 1000_f64.sqrt();
    let sa = 150e-6 * 9.80665 * 1000_f64.sqrt();
    assert!((default_gyro_sigma_rps() - sg).abs() < 1e-15);
    assert!((default_accel_sigma_mps2() - sa).abs() < 1e-15);
    for k in 0..3 {
        let factor = g.variance_factors()[k];
        assert!((f.rate_var[k] - sg * sg * factor).abs() < 1e-15);
        assert!((f.specific_force_var[k] - sa * sa * factor).abs() < 1e-12);
    }
}

#[test]
fn calibration_is_applied_before_the_solve() {
    let mut cfg = FusionConfig::default();
    cfg.calibration.gyro = ChannelCalibration {
        bias: vec![0.05, -0.04, 0.03, 0.0],
        scale: vec![1.02, 0.98, 1.0, 1.05],
    };
    let mut fuser = ImuFuser::new(&cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    let g = *fuser.gyro_geometry();
    let rate = [-0.3, 0.8, 0.05];
    let gc = counts_for(&g, rate, GYRO_LSB, &cfg.calibration.gyro);
    let f = fuser.fuse(&gc, &[0; 4], ALL_VALID);
    assert_within(f.rate, rate, rounding_bound(&g, GYRO_LSB, 0.98));
    // Without the calibration the channel biases would show up as a rate error far above rounding.
    let mut raw = ImuFuser::new(&FusionConfig::default(), GYRO_LSB, ACCEL_LSB).unwrap();
    let uncal = raw.fuse(&gc, &[0; 4], ALL_VALID).rate;
    assert!(
        (0..3).any(|k| (uncal[k] - rate[k]).abs() > 5.0 * rounding_bound(&g, GYRO_LSB, 1.0)[k])
    );
}

#[test]
fn invalid_channels_are_excluded_and_reduced_solvers_cached() {
    let cfg = FusionConfig::default();
    let mut fuser = ImuFuser::new(&cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    let g = *fuser.gyro_geometry();
    let cal = ChannelCalibration::default();
    let rate = [0.1, 0.2, -0.3];
    let force = [0.0, 0.0, -9.8];
    let mut gc = counts_for(&g, rate, GYRO_LSB, &cal);
    let ac = counts_for(&g, force, ACCEL_LSB, &cal);
    gc[2] = i16::MIN; // a failed channel's garbage

    let sigma2 = default_gyro_sigma_rps().powi(2);
    let three = WlsSolver::new(&g, 0b1011, &[sigma2; 4]).unwrap();
    let tol3 = {
        // Rounding error through the 3-channel gain: ‖G_k‖² = cov_kk/σ².
        let c = three.covariance();
        [0, 1, 2].map(|k| (3.0 * c[k][k] / sigma2).sqrt() * GYRO_LSB / 2.0)
    };
    for _ in 0..3 {
        let f = fuser.fuse(&gc, &ac, ALL_VALID & !(1 << 2));
        assert!(f.gyro_ok && f.accel_ok);
        assert_eq!(f.gyro_mask, 0b1011);
        assert_eq!(f.accel_mask, 0b1111);
        assert_within(f.rate, rate, tol3);
        assert_eq!(f.rate_var, three.solve(&[0.0; 4]).1);
        assert!((0..3).all(|k| f.rate_var[k] >= sigma2 * g.variance_factors()[k]));
        // Back to the full set with a healthy channel 2, then the reduced set again.
        let mut healthy = gc.clone();
        healthy[2] = counts_for(&g, rate, GYRO_LSB, &cal)[2];
        let full = fuser.fuse(&healthy, &ac, ALL_VALID);
        assert_eq!(full.gyro_mask, 0b1111);
        assert_within(full.rate, rate, rounding_bound(&g, GYRO_LSB, 1.0));
    }

    // Accel channel 0 invalid (bit 16).
    let f = fuser.fuse(&gc, &ac, 0x000E_000B);
    assert_eq!(f.accel_mask, 0b1110);
    assert_within(f.specific_force, force, [3.0 * ACCEL_LSB; 3]);
}

#[test]
fn fewer_than_three_valid_channels_is_not_ok() {
    let mut fuser = ImuFuser::new(&FusionConfig::default(), GYRO_LSB, ACCEL_LSB).unwrap();
    let f = fuser.fuse(&[100; 4], &[100; 4], 0x000F_0003);
    assert!(!f.gyro_ok && f.accel_ok);
    assert_eq!((f.rate, f.rate_var), ([0.0; 3], [0.0; 3]));
    assert_eq!(f.gyro_mask, 0b0011);
    let f = fuser.fuse(&[100; 4], &[100; 4], 0);
    assert!(!f.gyro_ok && !f.accel_ok);
    assert_eq!(f.specific_force, [0.0; 3]);
    // Short counts slices: missing channels count as invalid.
    let f = fuser.fuse(&[100; 2], &[100; 3], ALL_VALID);
    assert!(!f.gyro_ok && f.accel_ok);
    assert_eq!(f.accel_mask, 0b0111);
    // Full IPC-sized arrays: channels beyond N are ignored.
    let f = fuser.fuse(&[0; 16], &[0; 16], u32::MAX);
    assert!(f.gyro_ok && f.accel_ok);
    assert_eq!(f.rate, [0.0; 3]);
}

#[test]
fn config_parses_from_toml_and_errors_name_fields() {
    let text = r#"
        [geometry.gyro]
        kind = "axes"
        axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 1], [1, -1, 1]]
        [noise]
        gyro_sigma_rps = [0.005, 0.005, 0.005, 0.006, 0.007]
        accel_sigma_mps2 = 0.05
        [calibration.accel]
        scale = [1.0, 1.01, 0.99, 1.0]
    "#;
    let cfg: FusionConfig = toml::from_str(text).unwrap();
    cfg.validate().unwrap();
    assert_eq!(cfg.noise.accel_sigma_mps2, ChannelNoise::Uniform(0.05));
    let fuser = ImuFuser::new(&cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    assert_eq!(fuser.gyro_geometry().n(), 5);
    assert_eq!(fuser.gyro_geometry().parity_dimension(), 2);
    assert_eq!(fuser.accel_geometry().n(), 4);

    let e = toml::from_str::<FusionConfig>("[noise]\ngyro_sigma = 0.1").unwrap_err();
    assert!(e.to_string().contains("unknown field"), "{e}");

    let err = |t: &str| {
        toml::from_str::<FusionConfig>(t)
            .unwrap()
            .validate()
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        err("[noise]\ngyro_sigma_rps = [0.1, 0.1, 0.1]"),
        "noise.gyro_sigma_rps = 3 entries: must be one number or have 4 entries (one per channel)"
    );
    assert_eq!(
        err("[noise]\naccel_sigma_mps2 = [0.1, -0.1, 0.1, 0.1]"),
        "noise.accel_sigma_mps2[1] = -0.1: must be finite and > 0"
    );
    assert_eq!(
        err("[noise]\ngyro_sigma_rps = 0"),
        "noise.gyro_sigma_rps = 0: must be finite and > 0"
    );
    assert_eq!(
        err("[calibration.accel]\nscale = [1, 0, 1, 1]"),
        "calibration.accel.scale[1] = 0: must be finite and > 0"
    );
    assert_eq!(
        err("[calibration.gyro]\nbias = [0.1]"),
        "calibration.gyro.bias = 1 entries: must have 4 entries (one per channel) or be empty"
    );
    assert_eq!(
        err("[geometry.accel]\nkind = \"axes\"\naxes = [[1, 0, 0], [0, 1, 0]]"),
        "geometry.accel.axes = 2 axes: must have 3..=16 axes"
    );
    let e = ImuFuser::new(&FusionConfig::default(), 0.0, ACCEL_LSB).unwrap_err();
    assert_eq!(e.to_string(), "gyro_lsb = 0: must be finite and > 0");
    let e = ImuFuser::new(&FusionConfig::default(), GYRO_LSB, f64::NAN).unwrap_err();
    assert_eq!(e.field, "accel_lsb");
}
