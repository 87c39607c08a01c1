//! Altitude estimator: convergence, steady-state variance against the Kalman–Bucy closed form,
//! consistency of the reported variance, rejection of bad samples, gap resets.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, StandardNormal};
use rins_altimeter::{AltimeterConfig, AltitudeEstimator, AltitudeOutput};
use rins_earth::isa::{altitude_per_pascal, altitude_to_pressure};

const QNH: f64 = 101_325.0;
const DT_US: u64 = 20_000; // 50 Hz

/// Height variance of one sample at height h: (dh/dp · σ_p)².
fn measurement_var(cfg: &AltimeterConfig, h: f64) -> f64 {
    (altitude_per_pascal(altitude_to_pressure(h, cfg.qnh_pa), cfg.qnh_pa) * cfg.pressure_noise_pa)
        .powi(2)
}

/// Steady state of the continuous constant-velocity filter with acceleration PSD q and
/// measurement PSD r = R·Δt: P_hh = √2 q^¼ r^¾, P_vv = √2 q^¾ r^¼.
fn kalman_bucy_steady_state(q: f64, r_var: f64, dt: f64) -> (f64, f64) {
    let r = r_var * dt;
    (
        2f64.sqrt() * q.powf(0.25) * r.powf(0.75),
        2f64.sqrt() * q.powf(0.75) * r.powf(0.25),
    )
}

fn run_profile(
    cfg: &AltimeterConfig,
    seed: u64,
    samples: usize,
    height: impl Fn(f64) -> f64,
) -> Vec<(f64, AltitudeOutput)> {
    let mut est = AltitudeEstimator::new(cfg.clone()).unwrap();
    let noise = Normal::new(0.0, cfg.pressure_noise_pa).unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..samples)
        .map(|k| {
            let t = k as f64 * DT_US as f64 * 1e-6;
            let p = altitude_to_pressure(height(t), cfg.qnh_pa) + noise.sample(&mut rng);
            (t, est.update(1_000_000 + k as u64 * DT_US, p))
        })
        .collect()
}

#[test]
fn static_variance_settles_at_the_steady_state() {
    for q in [0.5, 0.01] {
        let cfg = AltimeterConfig {
            vertical_accel_psd: q,
            ..AltimeterConfig::default()
        };
        let out = run_profile(&cfg, 1, 1500, |_| 200.0);
        let r = measurement_var(&cfg, 200.0);
        let (phh, pvv) = kalman_bucy_steady_state(q, r, DT_US as f64 * 1e-6);
        let last = out.last().unwrap().1;
        assert!(last.valid);
        // Sampling makes the discrete posterior differ from the continuous one by O(ω·Δt).
        assert!(
            (last.height_var / phh - 1.0).abs() < 0.1,
            "q {q}: {} vs {phh}",
            last.height_var
        );
        assert!(
            (last.vertical_speed_var / pvv - 1.0).abs() < 0.1,
            "q {q}: {} vs {pvv}",
            last.vertical_speed_var
        );
        // Settled: unchanged over the last second (up to the ~2e-5 jitter of R with the noisy
        // pressure, see below), and well below a single sample's variance.
        let a_second_before = out[out.len() - 51].1;
        assert!((a_second_before.height_var / last.height_var - 1.0).abs() < 1e-4);
        assert!(last.height_var < r);
        // The first sample carries one measurement's variance (evaluated at the noisy pressure,
        // which moves dh/dp by a relative (1 − e)·σ_p/p ≈ 2e-5).
        assert!((out[0].1.height_var / r - 1.0).abs() < 1e-4);
    }
}

#[test]
fn constant_climb_converges_to_the_true_rate() {
    let rate = 5.0;
    for (q, seed) in [(0.5, 2), (0.01, 3)] {
        let cfg = AltimeterConfig {
            vertical_accel_psd: q,
            ..AltimeterConfig::default()
        };
        let out = run_profile(&cfg, seed, 3000, |t| 100.0 + rate * t);
        // Tolerance from the filter's own steady state: 4σ of the vertical-speed estimate.
        let r = measurement_var(&cfg, 300.0);
        let (phh, pvv) = kalman_bucy_steady_state(q, r, DT_US as f64 * 1e-6);
        for (t, o) in out.iter().skip(1000) {
            assert!(
                (o.vertical_speed_mps - rate).abs() < 4.0 * pvv.sqrt(),
                "q {q} t {t}: {} m/s",
                o.vertical_speed_mps
            );
            assert!((o.height_m - (100.0 + rate * t)).abs() < 4.0 * phh.sqrt());
        }
        // The mean over the last 40 s is far tighter than one estimate.
        let tail = &out[1000..];
        let mean = tail.iter().map(|(_, o)| o.vertical_speed_mps).sum::<f64>() / tail.len() as f64;
        assert!((mean - rate).abs() < pvv.sqrt(), "q {q}: mean {mean}");
    }
}

/// When the truth follows the filter's own model (white vertical acceleration of PSD q), the
/// reported variances are the actual mean squared errors. Checked over independent runs.
#[test]
fn reported_variance_matches_actual_error() {
    let cfg = AltimeterConfig::default();
    let q = cfg.vertical_accel_psd;
    let dt = DT_US as f64 * 1e-6;
    // Exact discretisation of white acceleration: (Δh, Δv) ~ N(0, Q), sampled by Cholesky.
    let (q00, q01, q11) = (q * dt.powi(3) / 3.0, q * dt * dt / 2.0, q * dt);
    let l00 = q00.sqrt();
    let l10 = q01 / l00;
    let l11 = (q11 - l10 * l10).sqrt();
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let noise = Normal::new(0.0, cfg.pressure_noise_pa).unwrap();
    const RUNS: usize = 2000;
    let (mut se_h, mut se_v, mut var_h, mut var_v) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..RUNS {
        let mut est = AltitudeEstimator::new(cfg.clone()).unwrap();
        // The filter starts at v = 0 with σ_v0: draw the truth from that prior.
        let (mut h, mut v) = (
            500.0,
            cfg.initial_vertical_speed_sigma_mps * {
                let n: f64 = StandardNormal.sample(&mut rng);
                n
            },
        );
        let mut out = AltitudeOutput::default();
        for k in 0..250u64 {
            if k > 0 {
                let (a, b): (f64, f64) = (
                    StandardNormal.sample(&mut rng),
                    StandardNormal.sample(&mut rng),
                );
                h += v * dt + l00 * a;
                v += l10 * a + l11 * b;
            }
            out = est.update(
                k * DT_US,
                altitude_to_pressure(h, QNH) + noise.sample(&mut rng),
            );
        }
        se_h += (out.height_m - h).powi(2);
        se_v += (out.vertical_speed_mps - v).powi(2);
        var_h += out.height_var;
        var_v += out.vertical_speed_var;
    }
    // Mean of RUNS squared Gaussian errors: relative standard error √(2/RUNS) ≈ 3 %; allow 5σ.
    let tol = 5.0 * (2.0 / RUNS as f64).sqrt();
    assert!(
        (se_h / var_h - 1.0).abs() < tol,
        "height: mse/var = {}",
        se_h / var_h
    );
    assert!(
        (se_v / var_v - 1.0).abs() < tol,
        "speed: mse/var = {}",
        se_v / var_v
    );
}

#[test]
fn bad_pressure_is_rejected_without_poisoning_the_state() {
    let mut est = AltitudeEstimator::new(AltimeterConfig::default()).unwrap();
    let before = est.update(0, 101_325.0);
    assert!(before.valid);
    let first = est.update(0, f64::NAN);
    assert!(!first.valid);
    assert_eq!(
        AltitudeOutput {
            valid: true,
            ..first
        },
        before,
        "a rejected sample repeats the last estimate"
    );
    for (k, p) in [
        f64::INFINITY,
        -1.0,
        0.0,
        29_999.0,
        110_001.0,
        f64::NEG_INFINITY,
    ]
    .into_iter()
    .enumerate()
    {
        let o = est.update(20_000 * (k as u64 + 1), p);
        assert!(!o.valid, "{p} accepted");
        assert!(o.height_m.is_finite() && o.height_var.is_finite());
    }
    assert_eq!(est.rejected_count(), 7);
    let o = est.update(200_000, 101_325.0);
    assert!(o.valid && o.height_m.abs() < 1.0 && o.vertical_speed_mps.is_finite());
    assert_eq!(est.reset_count(), 0);

    // Before any good sample: invalid zeros, not NaN.
    let mut fresh = AltitudeEstimator::new(AltimeterConfig::default()).unwrap();
    assert_eq!(fresh.update(0, f64::NAN), AltitudeOutput::default());
}

#[test]
fn gaps_and_backward_time_restart_the_filter() {
    let cfg = AltimeterConfig::default();
    let mut est = AltitudeEstimator::new(cfg.clone()).unwrap();
    let p = |h| altitude_to_pressure(h, QNH);
    for k in 0..100u64 {
        est.update(k * DT_US, p(0.1 * k as f64));
    }
    // 2 s gap (> max_dt_s = 1 s): restart at the new height with one measurement's variance.
    let t = 99 * DT_US + 2_000_000;
    let o = est.update(t, p(500.0));
    assert_eq!(est.reset_count(), 1);
    assert!((o.height_m - 500.0).abs() < 1e-6 && o.vertical_speed_mps == 0.0);
    assert!((o.height_var / measurement_var(&cfg, 500.0) - 1.0).abs() < 1e-6);
    assert!((o.vertical_speed_var - 25.0).abs() < 1e-12);
    // A gap just under the limit is bridged.
    est.update(t + 999_999, p(500.0));
    assert_eq!(est.reset_count(), 1);
    // Time running backwards restarts too.
    est.update(t, p(500.0));
    assert_eq!(est.reset_count(), 2);
}

#[test]
fn config_defaults_parse_and_validation() {
    let cfg: AltimeterConfig = toml::from_str("qnh_pa = 102000\nmax_dt_s = 0.5").unwrap();
    assert_eq!(cfg.qnh_pa, 102_000.0);
    assert_eq!(
        cfg.pressure_noise_pa,
        AltimeterConfig::default().pressure_noise_pa
    );
    cfg.validate().unwrap();
    let e = toml::from_str::<AltimeterConfig>("qnh = 102000").unwrap_err();
    assert!(e.to_string().contains("unknown field"), "{e}");

    let err = |cfg: AltimeterConfig| AltitudeEstimator::new(cfg).unwrap_err().to_string();
    let d = AltimeterConfig::default;
    assert_eq!(
        err(AltimeterConfig {
            qnh_pa: 5000.0,
            ..d()
        }),
        "qnh_pa = 5000: must be in 80000..=110000"
    );
    assert_eq!(
        err(AltimeterConfig {
            pressure_noise_pa: 0.0,
            ..d()
        }),
        "pressure_noise_pa = 0: must be finite and > 0"
    );
    assert_eq!(
        err(AltimeterConfig {
            vertical_accel_psd: f64::NAN,
            ..d()
        }),
        "vertical_accel_psd = NaN: must be finite and > 0"
    );
    assert_eq!(
        err(AltimeterConfig {
            max_dt_s: -1.0,
            ..d()
        }),
        "max_dt_s = -1: must be finite and > 0"
    );
    assert_eq!(
        err(AltimeterConfig {
            max_pressure_pa: 20_000.0,
            ..d()
        }),
        "max_pressure_pa = 20000: must be finite and > min_pressure_pa (30000)"
    );
}
