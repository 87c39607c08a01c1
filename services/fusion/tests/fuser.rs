//! ImuFuser: counts in, body rate and specific force out, honouring the valid mask.

use ipc_types::{ChannelState, FaultReason, FusedImu, RawImu, SensorType, fused_flags, status};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::config::{default_accel_sigma_mps2, default_gyro_sigma_rps};
use rins_fusion::{
    ChannelCalibration, ChannelNoise, FusionConfig, FusionMethod, Geometry, GeometryConfig,
    ImuFuser, ImuSample, RestBiasState, WlsSolver,
};

/// The fault flags of a sample: everything but the start-up rest-bias window, which these tests
/// do not look at.
fn fault_flags(f: &rins_fusion::Fused) -> u32 {
    f.flags() & !fused_flags::GYRO_REST_BIAS_PENDING
}

const GYRO_LSB: f64 = 0.0017; // ≈ ±200 °/s over 12 bits
const ACCEL_LSB: f64 = 0.0479; // ≈ ±10 g over 12 bits
const ALL_VALID: u32 = 0x000F_000F;

/// Channel variance the fuser uses: sensor noise plus quantisation, σ² + lsb²/12.
fn channel_variance(sigma: f64, lsb: f64) -> f64 {
    sigma * sigma + lsb * lsb / 12.0
}

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
    // The converter's quantisation noise lsb²/12 adds to the channel variance.
    let (vg, va) = (
        channel_variance(sg, GYRO_LSB),
        channel_variance(sa, ACCEL_LSB),
    );
    for k in 0..3 {
        let factor = g.variance_factors()[k];
        assert!((f.rate_var[k] - vg * factor).abs() < 1e-15);
        assert!((f.specific_force_var[k] - va * factor).abs() < 1e-12);
    }
    // Fault-free: every channel Ok, no flag, parity statistic tiny (rounding only).
    assert_eq!(fault_flags(&f), 0);
    assert!(
        f.gyro_status.states[..4]
            .iter()
            .all(|s| *s == ChannelState::Ok)
    );
    assert_eq!(f.gyro_status.states[4], ChannelState::Absent);
    assert_eq!(f.gyro_status.parity_dimension, 1);
    assert!(f.gyro_status.test_statistic < 1.0);
}

#[test]
fn calibration_is_applied_before_the_solve() {
    let mut cfg = FusionConfig::default();
    cfg.calibration.gyro = ChannelCalibration {
        bias: vec![0.05, -0.04, 0.03, 0.0],
        scale: vec![1.02, 0.98, 1.0, 1.05],
        ..Default::default()
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
fn invalid_channels_are_excluded_and_stay_excluded() {
    let cfg = FusionConfig::default();
    let mut fuser = ImuFuser::new(&cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    let g = *fuser.gyro_geometry();
    let cal = ChannelCalibration::default();
    let rate = [0.1, 0.2, -0.3];
    let force = [0.0, 0.0, -9.8];
    let mut gc = counts_for(&g, rate, GYRO_LSB, &cal);
    let ac = counts_for(&g, force, ACCEL_LSB, &cal);
    let healthy = gc.clone();
    gc[2] = i16::MIN; // a failed channel's garbage

    let sigma2 = channel_variance(default_gyro_sigma_rps(), GYRO_LSB);
    let three = WlsSolver::new(&g, 0b1011, &[sigma2; 4]).unwrap();
    let tol3 = {
        // Rounding error through the 3-channel gain: ‖G_k‖² = cov_kk/σ².
        let c = three.covariance();
        [0, 1, 2].map(|k| (3.0 * c[k][k] / sigma2).sqrt() * GYRO_LSB / 2.0)
    };
    let f = fuser.fuse(&gc, &ac, ALL_VALID & !(1 << 2));
    assert_eq!(f.gyro_status.reasons[2], FaultReason::Missing);
    assert_eq!(f.events.len(), 1);
    for _ in 0..3 {
        assert!(f.gyro_ok && f.accel_ok);
        assert_eq!(f.gyro_mask, 0b1011);
        assert_eq!(f.accel_mask, 0b1111);
        assert_within(f.rate, rate, tol3);
        assert_eq!(f.rate_var, three.solve(&[0.0; 4]).1);
        assert!((0..3).all(|k| f.rate_var[k] >= sigma2 * g.variance_factors()[k]));
        // Valid and healthy again: still excluded (exclusions latch).
        let f = fuser.fuse(&healthy, &ac, ALL_VALID);
        assert_eq!(f.gyro_mask, 0b1011);
        assert_eq!(f.gyro_status.states[2], ChannelState::Excluded);
        assert!(f.events.is_empty());
    }
    // Back only by command, after a probation out of the solution.
    assert_eq!(fuser.readmit(SensorType::Gyro, 2), Ok(true));
    for _ in 1..cfg.fdi.readmit_probation_samples {
        let f = fuser.fuse(&healthy, &ac, ALL_VALID);
        assert_eq!(f.gyro_mask, 0b1011);
        assert!(fuser.monitor(SensorType::Gyro).on_probation(2));
    }
    let f = fuser.fuse(&healthy, &ac, ALL_VALID);
    assert_eq!(f.gyro_mask, 0b1111);
    assert_within(f.rate, rate, rounding_bound(&g, GYRO_LSB, 1.0));
    assert_eq!(f.events.as_slice()[0].new_state, ChannelState::Ok);

    // Accel channel 0 invalid (bit 16).
    let f = fuser.fuse(&healthy, &ac, 0x000E_000F);
    assert_eq!(f.accel_mask, 0b1110);
    assert_eq!(f.accel_status.reasons[0], FaultReason::Missing);
    assert_eq!(f.events.as_slice()[0].sensor, SensorType::Accel);
    assert_within(f.specific_force, force, [3.0 * ACCEL_LSB; 3]);
}

#[test]
fn fewer_than_three_valid_channels_is_not_ok() {
    let new = || ImuFuser::new(&FusionConfig::default(), GYRO_LSB, ACCEL_LSB).unwrap();
    let f = new().fuse(&[100; 4], &[100; 4], 0x000F_0003);
    assert!(!f.gyro_ok && f.accel_ok);
    assert_eq!((f.rate, f.rate_var), ([0.0; 3], [0.0; 3]));
    assert_eq!(f.gyro_mask, 0b0011);
    assert_eq!(fault_flags(&f), fused_flags::GYRO_INSUFFICIENT);
    let f = new().fuse(&[100; 4], &[100; 4], 0);
    assert!(!f.gyro_ok && !f.accel_ok);
    assert_eq!(f.specific_force, [0.0; 3]);
    // Short counts slices: missing channels count as invalid.
    let f = new().fuse(&[100; 2], &[100; 3], ALL_VALID);
    assert!(!f.gyro_ok && f.accel_ok);
    assert_eq!(f.accel_mask, 0b0111);
    // Full IPC-sized arrays: channels beyond N are ignored.
    let f = new().fuse(&[0; 16], &[0; 16], u32::MAX);
    assert!(f.gyro_ok && f.accel_ok);
    assert_eq!(f.rate, [0.0; 3]);
    assert_eq!(f.gyro_status.states[4], ChannelState::Absent);
}

#[test]
fn config_parses_from_toml_and_errors_name_fields() {
    let text = r#"
        [geometry.gyro]
        kind = "axes"
        axes = [[1, 0, 0], [0, 1, 0], [0, 0, 1], [0.57735, 0.57735, 0.57735], [0.57735, -0.57735, 0.57735]]
        [noise]
        gyro_noise_density_dps_rthz = [0.01, 0.01, 0.01, 0.012, 0.014]
        accel_noise_density_ug_rthz = 160
        [calibration.accel]
        scale = [1.0, 1.01, 0.99, 1.0]
        [fdi]
        false_alarm_probability = 1e-10
        persistence_k = 4
        persistence_n = 6
        parity_noise = "adaptive"
        stuck_samples = 25
    "#;
    let cfg: FusionConfig = toml::from_str(text).unwrap();
    cfg.validate().unwrap();
    assert_eq!(
        cfg.noise.accel_noise_density_ug_rthz,
        ChannelNoise::Uniform(160.0)
    );
    // The per-sample σ is the density times √rate, at the block's rate.
    let sigmas = cfg.channel_sigmas(ipc_types::SensorType::Gyro).unwrap();
    assert!(
        (sigmas[4] - 0.014f64.to_radians() * 1000f64.sqrt()).abs() < 1e-15,
        "{sigmas:?}"
    );
    let mut fast = cfg.clone();
    fast.block.imu_rate_hz = 4000.0;
    let fast_sigmas = fast.channel_sigmas(ipc_types::SensorType::Gyro).unwrap();
    assert!(
        (fast_sigmas[4] / sigmas[4] - 2.0).abs() < 1e-12,
        "{fast_sigmas:?}"
    );
    assert_eq!(
        (
            cfg.fdi.persistence_k,
            cfg.fdi.persistence_n,
            cfg.fdi.stuck_samples
        ),
        (4, 6, 25)
    );
    assert_eq!(cfg.fdi.parity_noise, rins_fusion::ParityNoise::Adaptive);
    assert_eq!(cfg.fdi.noise_window, 200, "unset keys keep their defaults");
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
        err("[noise]\ngyro_noise_density_dps_rthz = [0.1, 0.1, 0.1]"),
        "noise.gyro_noise_density_dps_rthz = 3 entries: must be one number or have 4 entries (one per channel)"
    );
    assert_eq!(
        err("[noise]\naccel_noise_density_ug_rthz = [100, -100, 100, 100]"),
        "noise.accel_noise_density_ug_rthz[1] = -100: must be in [1e-9, 1e6]"
    );
    assert_eq!(
        err("[noise]\ngyro_noise_density_dps_rthz = 0"),
        "noise.gyro_noise_density_dps_rthz = 0: must be in [1e-9, 1e6]"
    );
    // So large that σ² overflows and the least squares loses its solution.
    assert_eq!(
        err("[noise]\ngyro_noise_density_dps_rthz = 1e308"),
        "noise.gyro_noise_density_dps_rthz = 1e308: must be in [1e-9, 1e6]"
    );
    // Within the density's range, but a per-sample σ no least squares can weigh.
    assert_eq!(
        err("[noise]\ngyro_noise_density_dps_rthz = 1e5"),
        "noise.gyro_noise_density_dps_rthz = 100000: gives a per-sample σ of 5.519e4 at the IMU rate: must be in [1e-9, 1e3]"
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
    assert_eq!(
        err("[fdi]\npersistence_k = 9"),
        "fdi.persistence_k = 9: must be <= persistence_n (5)"
    );
    assert_eq!(
        err("[fdi]\npersistence_n = 17"),
        "fdi.persistence_n = 17: must be in 1..=16"
    );
    assert_eq!(
        err("[fdi]\nfalse_alarm_probability = 0"),
        "fdi.false_alarm_probability = 0: must be finite and > 0"
    );
    assert!(
        err("[fdi]\nfalse_alarm_probability = 0.5")
            .starts_with("fdi.false_alarm_probability = 0.5: must be below")
    );
    assert_eq!(
        err("[fdi]\nstuck_samples = 1"),
        "fdi.stuck_samples = 1: must be >= 2"
    );
    assert_eq!(
        err("[fdi]\nnoise_ratio = 1"),
        "fdi.noise_ratio = 1: must be finite and > 1"
    );
    assert_eq!(
        err("[fdi]\nstationary_rate_spread_rps = -1"),
        "fdi.stationary_rate_spread_rps = -1: must be finite and > 0"
    );
    assert_eq!(
        err("[fdi]\nreference_ratio = 0.5"),
        "fdi.reference_ratio = 0.5: must be finite and >= 1"
    );
    let e = toml::from_str::<FusionConfig>("[fdi]\nparity_noise = \"loud\"").unwrap_err();
    assert!(e.to_string().contains("unknown variant"), "{e}");
    let e = toml::from_str::<FusionConfig>("[fdi]\npersistence = 3").unwrap_err();
    assert!(e.to_string().contains("unknown field"), "{e}");
    let e = ImuFuser::new(
        &toml::from_str::<FusionConfig>("[fdi]\npersistence_k = 0").unwrap(),
        GYRO_LSB,
        ACCEL_LSB,
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "fdi.persistence_k = 0: must be >= 1");
    let e = ImuFuser::new(&FusionConfig::default(), 0.0, ACCEL_LSB).unwrap_err();
    assert_eq!(e.to_string(), "gyro_lsb = 0: must be finite and > 0");
    let e = ImuFuser::new(&FusionConfig::default(), GYRO_LSB, f64::NAN).unwrap_err();
    assert_eq!(e.field, "accel_lsb");
}

#[test]
fn method_kalman_and_rest_bias_keys_parse_and_errors_name_fields() {
    let text = r#"
        method = "kalman"
        rest_bias_s = 2.5
        [kalman.process_noise]
        gyro = 20.0
        accel = 500.0
    "#;
    let mut cfg: FusionConfig = toml::from_str(text).unwrap();
    cfg.block.imu_rate_hz = 500.0;
    cfg.validate().unwrap();
    assert_eq!(cfg.method, FusionMethod::Kalman);
    assert_eq!(cfg.sample_period_s(), 0.002);
    assert_eq!(
        (
            cfg.kalman.process_noise.gyro,
            cfg.kalman.process_noise.accel
        ),
        (20.0, 500.0)
    );
    assert_eq!(cfg.rest_bias_samples().unwrap(), 1250);
    let fuser = ImuFuser::new(&cfg, GYRO_LSB, ACCEL_LSB).unwrap();
    assert_eq!(fuser.method(), FusionMethod::Kalman);
    assert_eq!(fuser.rest_bias_state(), RestBiasState::Collecting);

    let d = FusionConfig::default();
    assert_eq!(d.method, FusionMethod::Wls);
    assert_eq!((d.rest_bias_s, d.block.imu_rate_hz), (1.0, 1000.0));
    assert_eq!(d.rest_bias_samples().unwrap(), 1000);
    let off: FusionConfig = toml::from_str("rest_bias_s = 0").unwrap();
    assert_eq!(off.rest_bias_samples().unwrap(), 0);
    let fuser = ImuFuser::new(&off, GYRO_LSB, ACCEL_LSB).unwrap();
    assert_eq!(fuser.rest_bias_state(), RestBiasState::Disabled);

    let err = |t: &str| {
        toml::from_str::<FusionConfig>(t)
            .unwrap()
            .validate()
            .unwrap_err()
            .to_string()
    };
    assert_eq!(
        err("[kalman.process_noise]\ngyro = -1"),
        "kalman.process_noise.gyro = -1: must be finite and > 0"
    );
    // The rate is the device's, not a [fusion] key.
    for old in ["sample_rate_hz = 500", "[kalman]\nsample_period_s = 0.002"] {
        assert!(toml::from_str::<FusionConfig>(old).is_err(), "{old}");
    }
    assert_eq!(
        err("rest_bias_s = -1"),
        "rest_bias_s = -1: must be in 0..=600 s (0 disables it)"
    );
    assert_eq!(
        err("rest_bias_s = 0.005"),
        "rest_bias_s = 0.005: must span at least 10 samples at device.imu_rate_hz = 1000 (or be 0)"
    );
    let mut zero = FusionConfig::default();
    zero.block.imu_rate_hz = 0.0;
    assert_eq!(
        zero.validate().unwrap_err().to_string(),
        "device.imu_rate_hz = 0: must be in 1..=100000 Hz"
    );
    // The stationary block is in seconds: 0.2 s is 8 samples at 40 Hz, too few for a spread.
    let mut slow = FusionConfig::default();
    slow.block.imu_rate_hz = 40.0;
    slow.rest_bias_s = 0.0;
    assert_eq!(
        slow.validate().unwrap_err().to_string(),
        "fdi.stationary_window_s = 0.2: must span at least 10 samples at device.imu_rate_hz = 40"
    );
    slow.block.imu_rate_hz = 100.0;
    slow.validate().unwrap();
    let e = toml::from_str::<FusionConfig>("method = \"median\"").unwrap_err();
    assert!(e.to_string().contains("unknown variant"), "{e}");
    let e = ImuFuser::new(
        &toml::from_str::<FusionConfig>("rest_bias_s = nan").unwrap(),
        GYRO_LSB,
        ACCEL_LSB,
    )
    .unwrap_err();
    assert_eq!(e.field, "rest_bias_s");
}

/// The rins.toml shipped with the project still parses, and its fusion table validates.
#[test]
fn shipped_config_fusion_table_parses() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../config/rins.toml"
    ))
    .unwrap();
    let root: toml::Table = toml::from_str(&text).unwrap();
    let fusion: FusionConfig = root["fusion"].clone().try_into().unwrap();
    fusion.validate().unwrap();
}

/// Noisy counts of a stationary block: rate 0, specific force `force`, default channel noise.
struct NoisyBlock {
    gyro: Geometry,
    accel: Geometry,
    rng: ChaCha8Rng,
    accel_bias: [f64; 4],
}

const FULL_GYRO_LSB: f64 = 300.0 * std::f64::consts::PI / 180.0 / 2048.0;
const FULL_ACCEL_LSB: f64 = 8.0 * 9.80665 / 2048.0;

impl NoisyBlock {
    fn counts(&mut self, rate: [f64; 3], force: [f64; 3]) -> ([i16; 4], [i16; 4]) {
        let mut one = |g: &Geometry, x: [f64; 3], sigma: f64, lsb: f64, bias: &[f64; 4]| {
            std::array::from_fn(|i| {
                let h = g.axes()[i];
                let n: f64 = StandardNormal.sample(&mut self.rng);
                let v = h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + bias[i] + sigma * n;
                (v / lsb).round().clamp(-2048.0, 2047.0) as i16
            })
        };
        let bias = self.accel_bias;
        let gyro = one(
            &self.gyro,
            rate,
            default_gyro_sigma_rps(),
            FULL_GYRO_LSB,
            &[0.0; 4],
        );
        let accel = one(
            &self.accel,
            force,
            default_accel_sigma_mps2(),
            FULL_ACCEL_LSB,
            &bias,
        );
        (gyro, accel)
    }
}

/// End to end through ImuFuser at the default settings: the stationary detector sees the block
/// at rest, a reference is taken, and an accelerometer bias step is isolated against it (N = 4);
/// the same step while moving is reported detected-not-isolated, with every channel Suspect.
#[test]
fn fuser_isolates_a_stationary_accelerometer_fault_and_reports_a_moving_one() {
    for moving in [false, true] {
        let mut fuser =
            ImuFuser::new(&FusionConfig::default(), FULL_GYRO_LSB, FULL_ACCEL_LSB).unwrap();
        let mut block = NoisyBlock {
            gyro: *fuser.gyro_geometry(),
            accel: *fuser.accel_geometry(),
            rng: ChaCha8Rng::seed_from_u64(17),
            accel_bias: [0.0; 4],
        };
        let force = [0.3, -0.2, -9.79];
        let motion = |k: u32| {
            if moving {
                [0.5 * (f64::from(k) * 0.02).sin(), 0.3, 0.0]
            } else {
                [0.0; 3]
            }
        };
        for k in 0..1000 {
            let (g, a) = block.counts(motion(k), force);
            let f = fuser.fuse(&g, &a, ALL_VALID);
            assert_eq!(fault_flags(&f), 0);
            assert!(f.events.is_empty());
        }
        let f = fuser.fuse(
            &block.counts(motion(1000), force).0,
            &block.counts(motion(1000), force).1,
            ALL_VALID,
        );
        assert_eq!(f.stationary, !moving);
        block.accel_bias[1] = 12.0 * default_accel_sigma_mps2();
        let mut log = Vec::new();
        let mut flagged = false;
        for k in 0..20 {
            let (g, a) = block.counts(motion(1001 + k), force);
            let f = fuser.fuse(&g, &a, ALL_VALID);
            log.extend_from_slice(f.events.as_slice());
            flagged |= fault_flags(&f) & fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED != 0;
            let mut msg = FusedImu::default();
            f.write_fdi(&mut msg);
            assert_eq!(msg.accel_state, f.accel_status.states.map(|s| s as u8));
            assert_eq!(msg.accel_reason[1], f.accel_status.reasons[1] as u8);
            assert_eq!(
                msg.accel_test_statistic,
                f.accel_status.test_statistic as f32
            );
            assert_eq!(msg.flags, fault_flags(&f));
        }
        let reason = fuser.monitor(SensorType::Accel).exclusion(1);
        if moving {
            assert_eq!(reason, FaultReason::None);
            assert!(flagged);
            assert!(
                log.iter().any(
                    |e| e.new_state == ChannelState::Suspect && e.reason == FaultReason::Parity
                )
            );
        } else {
            assert_eq!(reason, FaultReason::StationaryReference);
            let e = log
                .iter()
                .find(|e| e.new_state == ChannelState::Excluded)
                .unwrap();
            assert_eq!(
                (e.sensor, e.channel, e.reason),
                (SensorType::Accel, 1, FaultReason::StationaryReference)
            );
        }
        assert_eq!(fuser.monitor(SensorType::Gyro).active_mask(), 0b1111);
    }
}

/// Device error: every channel Suspect (DeviceError), none excluded; a module temperature out of
/// the calibrated range makes the channels on that sensor Suspect (Temperature). Both clear when
/// the condition does. `fuse_raw` reads status, temperatures and counts from the IPC frame.
#[test]
fn device_error_and_temperature_are_reported_not_excluded() {
    let mut cfg = FusionConfig::default();
    cfg.calibration.gyro.temperature_sensor = vec![0, 0, 1, 1];
    let mut fuser = ImuFuser::new(&cfg, FULL_GYRO_LSB, FULL_ACCEL_LSB).unwrap();
    let mut block = NoisyBlock {
        gyro: *fuser.gyro_geometry(),
        accel: *fuser.accel_geometry(),
        rng: ChaCha8Rng::seed_from_u64(18),
        accel_bias: [0.0; 4],
    };
    let mut raw = RawImu {
        n_gyro: 4,
        n_accel: 4,
        n_temperature: 2,
        valid_mask: ALL_VALID,
        ..RawImu::default()
    };
    let mut frame = |fuser: &mut ImuFuser, status: u32, temps: [f32; 2]| {
        let (g, a) = block.counts([0.1, 0.0, 0.0], [0.0, 0.0, -9.8]);
        raw.gyro_counts[..4].copy_from_slice(&g);
        raw.accel_counts[..4].copy_from_slice(&a);
        raw.status = status;
        raw.temperature_c[..2].copy_from_slice(&temps);
        fuser.fuse_raw(&raw)
    };
    let f = frame(&mut fuser, 0, [25.0, 30.0]);
    assert!(
        f.gyro_status.states[..4]
            .iter()
            .all(|s| *s == ChannelState::Ok)
    );
    let f = frame(&mut fuser, status::DEVICE_ERROR, [25.0, 30.0]);
    assert!(f.gyro_status.device_error && f.accel_status.device_error);
    for st in [&f.gyro_status, &f.accel_status] {
        assert!(st.states[..4].iter().all(|s| *s == ChannelState::Suspect));
        assert!(
            st.reasons[..4]
                .iter()
                .all(|r| *r == FaultReason::DeviceError)
        );
    }
    assert_eq!(f.events.len(), 8);
    assert_eq!((f.gyro_mask, f.accel_mask), (0b1111, 0b1111));
    let f = frame(&mut fuser, 0, [25.0, 140.0]);
    assert_eq!(
        &f.gyro_status.reasons[..4],
        &[
            FaultReason::None,
            FaultReason::None,
            FaultReason::Temperature,
            FaultReason::Temperature
        ]
    );
    assert_eq!(
        f.accel_status.reasons[0],
        FaultReason::None,
        "accelerometers read sensor 0"
    );
    let f = frame(&mut fuser, 0, [25.0, f32::NAN]);
    assert_eq!(f.gyro_status.states[3], ChannelState::Suspect);
    let f = frame(&mut fuser, 0, [25.0, 30.0]);
    assert!(
        f.gyro_status.states[..4]
            .iter()
            .all(|s| *s == ChannelState::Ok)
    );
    assert_eq!(f.events.len(), 2);
    assert_eq!(fuser.monitor(SensorType::Gyro).active_mask(), 0b1111);

    // fuse_raw and fuse_sample agree.
    let mut a = fuser.clone();
    let mut b = fuser.clone();
    let (g, ac) = block.counts([0.2, 0.1, 0.0], [0.0, 0.0, -9.8]);
    raw.gyro_counts[..4].copy_from_slice(&g);
    raw.accel_counts[..4].copy_from_slice(&ac);
    raw.status = 0;
    let temps = [25.0f32, 30.0];
    raw.temperature_c[..2].copy_from_slice(&temps);
    let fa = a.fuse_raw(&raw);
    let fb = b.fuse_sample(&ImuSample {
        gyro_counts: &g,
        accel_counts: &ac,
        valid_mask: ALL_VALID,
        status: 0,
        temperatures_c: &temps,
    });
    assert_eq!(fa, fb);
    assert!(fuser.readmit(SensorType::Accel, 4).is_err());
}
