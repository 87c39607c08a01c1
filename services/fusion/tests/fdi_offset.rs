//! The learnt parity offset: uncalibrated channel biases do not raise alarms, faults still do,
//! and the offset survives a reconfiguration exactly.

mod common;

use common::{ACCEL_SIGMA, Fault, Rig, dodecahedron, pyramid4};
use ipc_types::{FaultReason, SensorType};
use proptest::prelude::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use rins_fusion::ParitySpace;
use rins_fusion::fdi::{FdiConfig, MAX_PARITY};
use rins_fusion::geometry::MAX_CHANNELS;

/// A rig with per-channel biases `bias_sigmas` × σ (turn-on biases calibration did not remove).
fn biased_rig(
    cfg: &FdiConfig,
    geometry: rins_fusion::Geometry,
    bias_sigmas: &[f64],
    seed: u64,
) -> Rig {
    let mut rig = Rig::builder(SensorType::Accel)
        .geometry(geometry)
        .config(cfg)
        .seed(seed)
        .build();
    for (i, b) in bias_sigmas.iter().enumerate() {
        rig.inject(i, Fault::Bias(b * ACCEL_SIGMA));
    }
    rig
}

const BIASES: [f64; 6] = [1.5, -1.0, 0.5, 2.0, -0.7, 1.2];

/// Channel biases (in σ) of 2σ in the parity-visible direction plus a part H·y that the solution
/// absorbs as a bias of x (invisible to parity).
fn pyramid_biases() -> [f64; 4] {
    let g = pyramid4();
    let space = ParitySpace::new(&g, 0b1111, &[1.0; 4]).unwrap();
    let v = space.basis()[0];
    let y = [0.3, -0.2, 0.5];
    std::array::from_fn(|i| {
        let h = g.axes()[i];
        2.0 * v[i] + h[0] * y[0] + h[1] * y[1] + h[2] * y[2]
    })
}

/// These checks are about the mechanism at a threshold where alarms are frequent enough to count:
/// χ² per-sample threshold from a persistent false-alarm probability of 1e-7.
fn at_1e7() -> FdiConfig {
    FdiConfig {
        false_alarm_probability: 1e-7,
        ..FdiConfig::default()
    }
}

#[test]
fn channel_biases_are_learnt_not_alarmed() {
    let x = [0.2, -0.3, -9.8];
    let biases = pyramid_biases();
    // Without the offset estimate the biases alone alarm over and over.
    let off = FdiConfig {
        parity_offset_window: 0,
        ..at_1e7()
    };
    let mut rig = biased_rig(&off, pyramid4(), &biases, 1);
    let mut t_sum = 0.0;
    let alarms = (0..100_000)
        .filter(|_| {
            let st = rig.step(x, false).1;
            t_sum += st.test_statistic;
            st.detected_not_isolated
        })
        .count();
    // Mean T = 1 + offset² (offset 2/√1.058 after the quantisation noise): about 4.8.
    assert!((t_sum / 1e5 - 4.78).abs() < 0.1, "{}", t_sum / 1e5);
    assert!(alarms > 1000, "{alarms}");

    let cfg = at_1e7();
    let mut rig = biased_rig(&cfg, pyramid4(), &biases, 1);
    rig.learn(x, false);
    for k in 0..300_000 {
        let (_, st) = rig.step(x, false);
        assert!(
            !st.detected_not_isolated,
            "alarm at {k}, T = {}",
            st.test_statistic
        );
    }
    // A bias step on top is still declared at once.
    rig.inject(2, Fault::Bias((biases[2] + 10.0) * ACCEL_SIGMA));
    let delay = (1..=10).find(|_| rig.step(x, false).1.detected_not_isolated);
    assert!(delay.is_some());
}

/// Six biased channels: a fault is isolated and excluded; the carried-over offset of the five
/// remaining channels keeps them quiet afterwards.
#[test]
fn offset_is_carried_over_a_reconfiguration() {
    let x = [0.2, -0.3, -9.8];
    let cfg = at_1e7();
    let mut rig = biased_rig(&cfg, dodecahedron(), &BIASES, 2);
    rig.learn(x, false);
    for _ in 0..10_000 {
        assert!(!rig.step(x, false).1.detected_not_isolated);
    }
    rig.inject(5, Fault::Bias((BIASES[5] + 12.0) * ACCEL_SIGMA));
    for _ in 0..20 {
        rig.step(x, false);
    }
    assert_eq!(rig.monitor.exclusion(5), FaultReason::Parity);
    for k in 0..200_000 {
        let (_, st) = rig.step(x, false);
        assert!(!st.detected_not_isolated, "alarm at {k}");
    }
    assert_eq!(rig.monitor.active_mask(), 0b01_1111);
}

proptest! {
    /// carry_over(V β) = V' β for any channel biases β and any reduced set.
    #[test]
    fn carry_over_is_exact(beta in prop::collection::vec(-5.0..5.0f64, 6), dropped in 0usize..6) {
        let g = dodecahedron();
        let old = ParitySpace::new(&g, 0b11_1111, &[1.0; 6]).unwrap();
        let new = ParitySpace::new(&g, 0b11_1111 & !(1 << dropped), &[1.0; 6]).unwrap();
        let mut b = [0.0; MAX_CHANNELS];
        b[..6].copy_from_slice(&beta);
        let (mut p_old, mut p_new) = ([0.0; MAX_PARITY], [0.0; MAX_PARITY]);
        old.parity(&b, &mut p_old);
        new.parity(&b, &mut p_new);
        let carried = new.carry_over(&old, &p_old);
        for r in 0..new.dimension() {
            prop_assert!((carried[r] - p_new[r]).abs() < 1e-12);
        }
    }
}

/// The adaptive estimate skips samples above the threshold; its truncation correction is
/// E[T | T < x]/m, here checked against the closed form for m = 2 and by simulation for m = 3.
#[test]
fn truncation_correction_matches_closed_form_and_simulation() {
    let s = at_1e7().settings().unwrap();
    let y = s.thresholds[2] / 2.0;
    // P(1, y) = 1 − e^{−y}, P(2, y) = 1 − e^{−y}(1 + y).
    let closed = (1.0 - (-y).exp() * (1.0 + y)) / (1.0 - (-y).exp());
    assert!((s.truncation[2] - closed).abs() < 1e-12);
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let (mut sum, mut count) = (0.0, 0u32);
    for _ in 0..400_000 {
        let t: f64 = (0..3)
            .map(|_| StandardNormal.sample(&mut rng))
            .map(|v: f64| v * v)
            .sum();
        if t < s.thresholds[3] {
            sum += t;
            count += 1;
        }
    }
    let empirical = sum / f64::from(count) / 3.0;
    // Standard error ≈ √(2·3/N)/3 = 0.13 %.
    assert!(
        (empirical - s.truncation[3]).abs() < 0.006,
        "{empirical} vs {}",
        s.truncation[3]
    );
    assert!(s.truncation[3] < 0.99, "the correction matters");
}
