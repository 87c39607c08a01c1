//! Stance detectors: each fires at rest and not in swing, and rejects bad settings by name.

use rins_navigator::stance::{StanceConfig, StanceDetector, StanceTest};

const G: f64 = 9.81;
/// 200 Hz.
const DT: f64 = 0.005;
const REST_FORCE: [f64; 3] = [0.0, 0.0, -G];

fn shoe() -> StanceConfig {
    StanceConfig {
        window: 5,
        detector: StanceTest::Shoe {
            accel_sigma_mps2: 0.01,
            gyro_sigma_rps: 0.1f64.to_radians(),
            threshold: 1e5,
        },
        min_samples: 1,
        raise_after_samples: 0,
        raise_factor: 1.0,
        gait_exponent: 0.0,
        gait_time_constant_s: 1.0,
    }
}

#[test]
fn shoe_statistic_is_the_closed_form_and_separates_rest_from_swing() {
    let mut d = StanceDetector::new(shoe());
    // Not before the window is full.
    for _ in 0..4 {
        assert!(!d.push([0.0; 3], REST_FORCE, None, G, DT));
    }
    assert!(d.push([0.0; 3], REST_FORCE, None, G, DT));
    assert!(d.last_statistic().abs() < 1e-9);
    // A constant 0.01 rad/s rate: T = |ω|²/σ_ω² exactly (the specific force term is zero).
    for _ in 0..5 {
        d.push([0.0, 0.0, 0.01], REST_FORCE, None, G, DT);
    }
    let expected = (0.01 / 0.1f64.to_radians()).powi(2);
    assert!((d.last_statistic() - expected).abs() < 1e-6 * expected);
    // Swing: 3 rad/s and 5 m/s² of acceleration.
    for _ in 0..5 {
        assert!(!d.push([3.0, 0.0, 0.0], [5.0, 0.0, -G], None, G, DT));
    }
    // Back at rest, a full window later.
    let fired: Vec<bool> = (0..5)
        .map(|_| d.push([0.0; 3], REST_FORCE, None, G, DT))
        .collect();
    assert_eq!(fired, [false, false, false, false, true]);
}

#[test]
fn shoe_ignores_the_direction_of_gravity() {
    // A tilted foot at rest: the specific force is g along any direction.
    let mut d = StanceDetector::new(shoe());
    let f = [G * 0.6, 0.0, -G * 0.8];
    let fired = (0..5).map(|_| d.push([0.0; 3], f, None, G, DT)).last();
    assert_eq!(fired, Some(true));
}

#[test]
fn magnitude_thresholds_need_every_sample_of_the_window() {
    let mut d = StanceDetector::new(StanceConfig {
        window: 3,
        detector: StanceTest::Thresholds {
            accel_tolerance_mps2: 0.5,
            gyro_max_rps: 0.2,
        },
        min_samples: 1,
        raise_after_samples: 0,
        raise_factor: 1.0,
        gait_exponent: 0.0,
        gait_time_constant_s: 1.0,
    });
    assert!(!d.push([0.0; 3], REST_FORCE, None, G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, None, G, DT));
    assert!(d.push([0.0; 3], REST_FORCE, None, G, DT));
    // One rotating sample keeps the window out of stance for three samples.
    assert!(!d.push([0.3, 0.0, 0.0], REST_FORCE, None, G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, None, G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, None, G, DT));
    assert!(d.push([0.0; 3], REST_FORCE, None, G, DT));
    // |f| 1 m/s² off g is not stance.
    for _ in 0..3 {
        assert!(!d.push([0.0; 3], [0.0, 0.0, -G - 1.0], None, G, DT));
    }
}

#[test]
fn foot_pressure_decides_alone_and_a_missing_reading_is_swing() {
    let mut d = StanceDetector::new(StanceConfig {
        window: 1,
        detector: StanceTest::Fsr { threshold: 0.5 },
        min_samples: 1,
        raise_after_samples: 0,
        raise_factor: 1.0,
        gait_exponent: 0.0,
        gait_time_constant_s: 1.0,
    });
    assert!(d.push([5.0; 3], [9.0; 3], Some(0.8), G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.2), G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, None, G, DT));
}

#[test]
fn bad_settings_name_the_field() {
    let mut c = shoe();
    c.window = 0;
    assert_eq!(c.check(), Err(("window", 0.0)));
    c.window = 65;
    assert_eq!(c.check(), Err(("window", 65.0)));
    c = StanceConfig {
        window: 5,
        detector: StanceTest::Shoe {
            accel_sigma_mps2: 0.01,
            gyro_sigma_rps: f64::NAN,
            threshold: 1.0,
        },
        min_samples: 1,
        raise_after_samples: 0,
        raise_factor: 1.0,
        gait_exponent: 0.0,
        gait_time_constant_s: 1.0,
    };
    assert_eq!(c.check().map_err(|e| e.0), Err("gyro_sigma_rps"));
    c = shoe();
    c.min_samples = 0;
    assert_eq!(c.check(), Err(("min_samples", 0.0)));
    assert!(shoe().check().is_ok());
}

#[test]
fn stance_is_declared_only_after_min_samples_consecutive_detections() {
    let mut d = StanceDetector::new(StanceConfig {
        window: 1,
        detector: StanceTest::Fsr { threshold: 0.5 },
        min_samples: 3,
        raise_after_samples: 0,
        raise_factor: 1.0,
        gait_exponent: 0.0,
        gait_time_constant_s: 1.0,
    });
    // A two-sample touch is not stance; the third consecutive loaded sample is.
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.9), G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.9), G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.1), G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.9), G, DT));
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.9), G, DT));
    assert!(d.push([0.0; 3], REST_FORCE, Some(0.9), G, DT));
    assert!(d.push([0.0; 3], REST_FORCE, Some(0.9), G, DT));
    // One unloaded sample ends it at once.
    assert!(!d.push([0.0; 3], REST_FORCE, Some(0.1), G, DT));
}

#[test]
fn a_long_run_without_stance_raises_the_threshold_until_a_quiet_window_returns() {
    let mut d = StanceDetector::new(StanceConfig {
        raise_after_samples: 20,
        raise_factor: 10.0,
        ..shoe()
    });
    // A running stance, never as quiet as a walking one: 0.9 rad/s → T = (0.9/σ_ω)² ≈ 2.7e5,
    // between the threshold and ten times it.
    let busy = [0.9, 0.0, 0.0];
    let (t_busy, threshold) = ((0.9 / 0.1f64.to_radians()).powi(2), 1e5);
    assert!(t_busy > threshold && t_busy < 10.0 * threshold);
    for k in 0..19 {
        assert!(!d.push(busy, REST_FORCE, None, G, DT), "sample {k}");
    }
    assert!(!d.is_raised());
    // The 20th sample without stance raises it: from the next sample on the busy stance passes.
    assert!(!d.push(busy, REST_FORCE, None, G, DT));
    assert!(d.is_raised());
    assert!(d.push(busy, REST_FORCE, None, G, DT));
    // Swing, then a busy stance again: still raised (the stance was not quiet).
    for _ in 0..5 {
        assert!(!d.push([6.0, 0.0, 0.0], [5.0, 0.0, -G], None, G, DT));
    }
    let fired = (0..5).map(|_| d.push(busy, REST_FORCE, None, G, DT)).last();
    assert_eq!(fired, Some(true));
    assert!(d.is_raised());
    // A truly quiet window passes the base threshold and lowers it again.
    for _ in 0..5 {
        d.push([0.0; 3], REST_FORCE, None, G, DT);
    }
    assert!(!d.is_raised());
    let mut c = shoe();
    c.raise_factor = 0.5;
    assert_eq!(c.check(), Err(("raise_factor", 0.5)));
}

/// Decisions over `n` samples of rate `w` about x with the foot level (the last one returned).
fn hold(d: &mut StanceDetector, w: f64, n: usize) -> bool {
    (0..n)
        .map(|_| d.push([w, 0.0, 0.0], REST_FORCE, None, G, DT))
        .last()
        .unwrap_or(false)
}

#[test]
fn the_gait_adapted_threshold_passes_a_running_stance_and_tightens_at_rest() {
    let adaptive = StanceConfig {
        gait_exponent: 0.5,
        gait_time_constant_s: 1.0,
        ..shoe()
    };
    let (mut fixed, mut adapted) = (StanceDetector::new(shoe()), StanceDetector::new(adaptive));
    // A second of swing at 6 rad/s: the mean |ω|² climbs from 1 towards 36, to
    // 36 − 35 · 0.995²⁰⁰ = 23.1 (rad/s)², so the threshold becomes 1e5 · √23.1 = 4.8e5.
    for d in [&mut fixed, &mut adapted] {
        assert!(!hold(d, 6.0, 200));
    }
    // A running stance, 0.9 rad/s: T = (0.9 / σ_ω)² = 2.66e5, above γ and below the adapted one.
    assert!(!hold(&mut fixed, 0.9, 5));
    assert!(hold(&mut adapted, 0.9, 5));
    let expected = 1e5 * (36.0 - 35.0 * 0.995f64.powi(200) - 0.0).sqrt();
    let got = adapted.last_threshold();
    assert!(
        (got / expected - 1.0).abs() < 0.05,
        "{got} against {expected}"
    );
    // Ten seconds standing still: the mean |ω|² falls to 23 · 0.995²⁰⁰⁰ ≈ 1e-3, the threshold to
    // about 3e3, and a foot turning at 0.2 rad/s (T = 1.3e4) is no longer in stance; the fixed
    // threshold still calls it stance.
    assert!(hold(&mut fixed, 0.0, 2000));
    assert!(hold(&mut adapted, 0.0, 2000));
    assert!(hold(&mut fixed, 0.2, 5));
    assert!(!hold(&mut adapted, 0.2, 5));
    // Settings out of range are named.
    let bad = StanceConfig {
        gait_exponent: 3.0,
        ..shoe()
    };
    assert_eq!(bad.check(), Err(("gait_exponent", 3.0)));
    let bad = StanceConfig {
        gait_time_constant_s: 0.0,
        ..shoe()
    };
    assert_eq!(bad.check(), Err(("gait_time_constant_s", 0.0)));
}

#[test]
fn ared_is_the_rate_energy_alone() {
    let mut d = StanceDetector::new(StanceConfig {
        detector: StanceTest::Ared {
            gyro_sigma_rps: 0.01,
            threshold: 100.0,
        },
        ..shoe()
    });
    // A rate of 0.05 rad/s: T = (0.05 / 0.01)² = 25 < 100, whatever the specific force does
    // (SHOE's own term would see the 3 m/s² swing).
    let rocking = [0.0, 0.0, -G + 3.0];
    assert!(hold(&mut d, 0.0, 5));
    let fired = (0..5)
        .map(|_| d.push([0.05, 0.0, 0.0], rocking, None, G, DT))
        .last();
    assert_eq!(fired, Some(true));
    assert!(
        (d.last_statistic() - 25.0).abs() < 1e-9,
        "{}",
        d.last_statistic()
    );
    // 0.2 rad/s: T = 400, no stance.
    assert!(!hold(&mut d, 0.2, 5));
    let bad = StanceConfig {
        detector: StanceTest::Ared {
            gyro_sigma_rps: 0.0,
            threshold: 1.0,
        },
        ..shoe()
    };
    assert_eq!(bad.check(), Err(("gyro_sigma_rps", 0.0)));
}
