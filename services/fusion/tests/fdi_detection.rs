//! Parity detection and GLT isolation: false-alarm statistics, detection delay, isolation rate,
//! reconfiguration without a jump, two faults with N = 6.

mod common;

use common::{
    ACCEL_LSB, ACCEL_SIGMA, Fault, GYRO_LSB, GYRO_SIGMA, Rig, dodecahedron, pyramid4,
    random_vector, stacked_two,
};
use ipc_types::{ChannelState, FaultReason, SensorType};
use rand::Rng;
use rins_fusion::fdi::FdiConfig;
use rins_fusion::fdi::persistence::declared_false_alarm_probability;
use rins_fusion::{Geometry, WlsSolver};

fn any_alarm(rig: &Rig, st: &rins_fusion::SensorStatus) -> bool {
    st.detected_not_isolated || rig.monitor.active_mask() != rig.geometry.full_mask()
}

/// 10⁶ fault-free samples per sensor type at the default settings, with converter quantisation and
/// a slowly varying motion: no alarm, no exclusion, no event (expected 0.1 parity alarms per type
/// per 10⁶ samples, and < 1e-3 stuck alarms).
#[test]
fn a_million_fault_free_samples_raise_no_alarm() {
    let cfg = FdiConfig::default();
    for (sensor, sigma, lsb, scale, seed) in [
        (SensorType::Gyro, GYRO_SIGMA, GYRO_LSB, 0.5, 11),
        (SensorType::Accel, ACCEL_SIGMA, ACCEL_LSB, 9.81, 12),
    ] {
        let mut rig = Rig::builder(sensor)
            .sigma(sigma)
            .lsb(lsb)
            .config(&cfg)
            .seed(seed)
            .build();
        for k in 0..1_000_000u32 {
            let t = f64::from(k) * 1e-3;
            let x = [
                scale * (0.3 * t).sin(),
                0.2 * scale * (0.11 * t).cos(),
                -scale,
            ];
            let (est, st) = rig.step(x, false);
            assert!(est.ok);
            assert!(
                !any_alarm(&rig, &st),
                "{sensor:?}: alarm at sample {k}, T = {}",
                st.test_statistic
            );
            assert!(rig.events.is_empty());
        }
    }
}

/// At a high configured rate the number of declarations (rising edges) matches
/// C(n−1,k−1) α₁^k (1−α₁)^(n−k+1) per sample within 5 Poisson standard deviations (the
/// per-sample test alone: the mean-shift test is off).
#[test]
fn declared_false_alarm_rate_matches_the_arithmetic() {
    for (k, n, alpha) in [(3, 5, 2e-3), (2, 4, 1e-3), (1, 1, 1e-3)] {
        let cfg = FdiConfig {
            false_alarm_probability: alpha,
            persistence_k: k,
            persistence_n: n,
            mean_shift_window: 0,
            ..FdiConfig::default()
        };
        let settings = cfg.settings().unwrap();
        assert!(
            (declared_false_alarm_probability(settings.exceedance_probability, k, n) / alpha - 1.0)
                .abs()
                < 1e-9
        );
        let mut rig = Rig::builder(SensorType::Gyro)
            .exact()
            .config(&cfg)
            .seed(21)
            .build();
        const SAMPLES: u32 = 300_000;
        let mut declarations = 0u32;
        let mut previous = false;
        for _ in 0..SAMPLES {
            let (_, st) = rig.step([0.1, -0.2, 0.3], false);
            if st.detected_not_isolated && !previous {
                declarations += 1;
            }
            previous = st.detected_not_isolated;
        }
        let expected = alpha * f64::from(SAMPLES);
        assert!(
            (f64::from(declarations) - expected).abs() < 5.0 * expected.sqrt(),
            "k {k} n {n}: {declarations} declarations, expected {expected}"
        );
        // With N = 4 a declaration is never an exclusion.
        assert_eq!(rig.monitor.active_mask(), 0b1111);
    }
}

/// A bias of 2σ of one channel, which the per-sample test takes seconds to declare, is declared
/// by the mean-shift test within a tenth of a second; fault-free, the default settings stay
/// silent over five minutes at 1 kHz (the test's own false-alarm arithmetic is checked in
/// `mean_shift`'s unit tests).
#[test]
fn the_mean_shift_test_finds_a_two_sigma_bias_at_once_and_stays_silent_without_one() {
    // The default settings, a 2σ bias on gyro 1 after the learning phase.
    let cfg = FdiConfig::default();
    let mut rig = Rig::builder(SensorType::Gyro).config(&cfg).seed(23).build();
    let x = [0.1, -0.2, 0.3];
    for k in 0..300_000 {
        let (_, st) = rig.step(x, false);
        assert!(!st.detected_not_isolated, "false alarm at sample {k}");
    }
    rig.inject(1, Fault::Bias(2.0 * rig.sigma[1]));
    let found = (1..=2000).find(|_| rig.step(x, false).1.detected_not_isolated);
    let found = found.expect("a 2σ bias is declared");
    assert!(found <= 150, "declared after {found} samples");
    // Four channels: detected, not isolated, nobody excluded.
    assert_eq!(rig.monitor.active_mask(), 0b1111);
}

/// Bias on `channel` whose whitened parity signature has length `sigmas` (σ of the parity noise).
fn parity_sigma_bias(rig: &Rig, channel: usize, sigmas: f64) -> f64 {
    let space = rig.monitor.parity().unwrap();
    let w2: f64 = space
        .whitened_basis()
        .iter()
        .map(|row| row[channel] * row[channel])
        .sum();
    sigmas / w2.sqrt()
}

/// Samples from the fault start to the first declaration (flag or exclusion), 1-based.
fn detection_delay(rig: &mut Rig, x: [f64; 3], limit: u32) -> Option<u32> {
    (1..=limit).find(|_| {
        let (_, st) = rig.step(x, false);
        any_alarm(rig, &st) || st.states.contains(&ChannelState::Suspect)
    })
}

#[test]
fn five_sigma_bias_step_is_declared_within_ten_samples() {
    let cfg = FdiConfig::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64_compat(5);
    for (geometry, name) in [(pyramid4(), "pyramid"), (dodecahedron(), "dodecahedron")] {
        let mut worst = 0;
        for trial in 0..500u64 {
            let mut rig = Rig::builder(SensorType::Gyro)
                .geometry(geometry)
                .exact()
                .config(&cfg)
                .seed(100 + trial)
                .build();
            let x = random_vector(&mut rng, 1.0);
            rig.learn(x, false);
            for _ in 0..rng.random_range(5..30) {
                let (_, st) = rig.step(x, false);
                assert!(!any_alarm(&rig, &st));
            }
            let channel = rng.random_range(0..geometry.n());
            let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let bias = sign * parity_sigma_bias(&rig, channel, 5.0);
            rig.inject(channel, Fault::Bias(bias));
            let delay = detection_delay(&mut rig, x, 50).unwrap_or(u32::MAX);
            assert!(
                delay <= 10,
                "{name} trial {trial}: declared after {delay} samples"
            );
            worst = worst.max(delay);
        }
        assert!(worst >= 3, "k = 3 needs three samples");
    }
}

/// 1000 random single bias faults of 4–8 channel σ on random channels, N = 6: the excluded
/// channel is the faulty one in ≥ 99 % of the cases (dodecahedron and two skewed triads).
#[test]
fn random_single_faults_are_isolated_correctly_with_six_channels() {
    let cfg = FdiConfig::default();
    for (geometry, name, seed) in [
        (dodecahedron(), "dodecahedron", 7),
        (stacked_two(), "stacked", 8),
    ] {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64_compat(seed);
        let mut correct = 0;
        let mut delays = Vec::new();
        const TRIALS: u64 = 1000;
        for trial in 0..TRIALS {
            let mut rig = Rig::builder(SensorType::Gyro)
                .geometry(geometry)
                .exact()
                .config(&cfg)
                .seed(1000 * seed + trial)
                .build();
            let x = random_vector(&mut rng, 2.0);
            rig.learn(x, false);
            for _ in 0..rng.random_range(5..30) {
                rig.step(x, false);
            }
            let channel = rng.random_range(0..6);
            let size = rng.random_range(4.0..8.0) * GYRO_SIGMA;
            let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            rig.inject(channel, Fault::Bias(sign * size));
            let mut delay = None;
            for t in 1..=2000 {
                rig.step(x, false);
                if rig.monitor.active_mask() != 0b11_1111 {
                    delay = Some(t);
                    break;
                }
            }
            let delay = delay.unwrap_or_else(|| panic!("{name} trial {trial}: not isolated"));
            delays.push(delay);
            let excluded = (!rig.monitor.active_mask() & 0b11_1111).trailing_zeros() as usize;
            assert_eq!(rig.monitor.exclusion(excluded), FaultReason::Parity);
            if excluded == channel {
                correct += 1;
            }
        }
        delays.sort_unstable();
        let rate = f64::from(correct) / TRIALS as f64;
        assert!(rate >= 0.99, "{name}: {correct}/{TRIALS} correct");
        eprintln!(
            "{name}: {correct}/{TRIALS} correct, delay median {} p99 {} max {}",
            delays[delays.len() / 2],
            delays[delays.len() * 99 / 100],
            delays[delays.len() - 1]
        );
    }
}

/// Excluding the faulty channel leaves the solution unbiased: the mean after exclusion matches
/// the fault-free mean, and per sample the reduced solution differs from the fault-free full
/// solution only by the noise of the dropped channel (covariance C_reduced − C_full).
#[test]
fn reconfiguration_does_not_make_the_solution_jump() {
    let cfg = FdiConfig::default();
    for (geometry, faulty) in [(dodecahedron(), 2usize), (pyramid4(), 1)] {
        let n = geometry.n();
        let mut rig = Rig::builder(SensorType::Gyro)
            .geometry(geometry)
            .exact()
            .config(&cfg)
            .seed(77)
            .build();
        let x = [0.4, -0.3, 0.8];
        const M: usize = 2000;
        let mut before = [0.0; 3];
        for _ in 0..M {
            // Stationary (x is constant): 2000 samples are 10 stationary blocks.
            let (est, _) = rig.step(x, true);
            (0..3).for_each(|k| before[k] += est.x[k] / M as f64);
        }
        // (N = 4 isolates against the stationary reference that these blocks established.)
        let bias = 12.0 * GYRO_SIGMA;
        rig.inject(faulty, Fault::Bias(bias));
        for _ in 0..100 {
            if rig.monitor.active_mask() != geometry.full_mask() {
                break;
            }
            rig.step(x, true);
        }
        assert_eq!(
            rig.monitor.active_mask(),
            geometry.full_mask() & !(1 << faulty)
        );
        let var = vec![GYRO_SIGMA * GYRO_SIGMA; n];
        let full = WlsSolver::new(&geometry, geometry.full_mask(), &var).unwrap();
        let reduced = *rig.monitor.solver().unwrap();
        let (cf, cr) = (full.covariance(), reduced.covariance());
        let mut after = [0.0; 3];
        let mut diff2 = [0.0; 3];
        for _ in 0..M {
            let (mut z, counts, valid) = rig.sample(x);
            let (est, _) = rig.step_with(&z, &counts, valid, false);
            z[faulty] -= bias;
            let (clean, _) = full.solve(&z);
            for k in 0..3 {
                after[k] += est.x[k] / M as f64;
                diff2[k] += (est.x[k] - clean[k]).powi(2) / M as f64;
            }
        }
        for k in 0..3 {
            let se = ((cf[k][k] + cr[k][k]) / M as f64).sqrt();
            assert!(
                (after[k] - before[k]).abs() < 5.0 * se,
                "N {n} axis {k}: mean moved"
            );
            let predicted = cr[k][k] - cf[k][k];
            // The sample mean of a squared Gaussian has relative standard error √(2/M) = 3.2 %.
            // (An axis orthogonal to the dropped channel does not move at all.)
            assert!(
                (diff2[k] - predicted).abs() < 0.15 * predicted + 1e-9 * cr[k][k],
                "N {n} axis {k}: {} vs {predicted}",
                diff2[k]
            );
            // The step at the exclusion is no larger than the noise of the solution itself.
            assert!(predicted <= cr[k][k]);
        }
    }
}

/// N = 6 tolerates two faults: both isolated in turn; a third leaves N = 4, which detects but
/// cannot isolate (while moving) — reported, all candidates Suspect, still fused.
#[test]
fn six_channels_isolate_two_successive_faults_then_report_the_third() {
    let cfg = FdiConfig::default();
    let geometry: Geometry = dodecahedron();
    let mut rig = Rig::builder(SensorType::Accel)
        .geometry(geometry)
        .exact()
        .config(&cfg)
        .seed(9)
        .build();
    let x = [0.5, 1.0, -9.8];
    rig.learn(x, false);
    let step_until_excluded = |rig: &mut Rig, channel: usize| {
        rig.inject(channel, Fault::Bias(10.0 * ACCEL_SIGMA));
        for t in 1..=50 {
            rig.step(x, false);
            if rig.monitor.exclusion(channel) != FaultReason::None {
                return t;
            }
        }
        panic!("channel {channel} not isolated");
    };
    assert!(step_until_excluded(&mut rig, 4) <= 10);
    assert_eq!(rig.monitor.parity_dimension(), 2);
    assert!(step_until_excluded(&mut rig, 1) <= 10);
    assert_eq!(rig.monitor.active_mask(), 0b10_1101);
    assert_eq!(rig.monitor.parity_dimension(), 1);
    let (est, st) = rig.step(x, false);
    assert!(est.ok && !st.detected_not_isolated);
    assert_eq!(st.states[4], ChannelState::Excluded);
    assert_eq!(st.reasons[1], FaultReason::Parity);

    rig.inject(0, Fault::Bias(15.0 * ACCEL_SIGMA));
    let mut flagged = false;
    for _ in 0..20 {
        let (est, st) = rig.step(x, false);
        if st.detected_not_isolated {
            flagged = true;
            assert_eq!(est.mask, 0b10_1101, "still fused with all four");
            for ch in [0, 2, 3, 5] {
                assert_eq!(
                    (st.states[ch], st.reasons[ch]),
                    (ChannelState::Suspect, FaultReason::Parity)
                );
            }
        }
    }
    assert!(flagged);
    assert_eq!(
        rig.monitor.active_mask(),
        0b10_1101,
        "no exclusion without isolation"
    );
}

/// Extension for seeding ChaCha from a u64 in the tests.
trait SeedCompat {
    fn seed_from_u64_compat(seed: u64) -> Self;
}

impl SeedCompat for rand_chacha::ChaCha8Rng {
    fn seed_from_u64_compat(seed: u64) -> Self {
        rand::SeedableRng::seed_from_u64(seed)
    }
}
