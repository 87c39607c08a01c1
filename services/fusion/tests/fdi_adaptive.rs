//! `parity_noise = "adaptive"`: real noise 3× the configured σ (rotor vibration).

mod common;

use common::{Fault, GYRO_SIGMA, Rig, dodecahedron, pyramid4};
use ipc_types::{FaultReason, SensorType};
use rins_fusion::fdi::{FdiConfig, ParityNoise};

/// A rig whose channels are 3× noisier than the configuration says.
fn vibrating_rig(mode: ParityNoise, geometry: rins_fusion::Geometry, seed: u64) -> Rig {
    let cfg = FdiConfig {
        parity_noise: mode,
        ..FdiConfig::default()
    };
    let mut rig = Rig::builder(SensorType::Gyro)
        .geometry(geometry)
        .exact()
        .config(&cfg)
        .seed(seed)
        .build();
    let n = rig.n();
    rig.sigma[..n].iter_mut().for_each(|s| *s *= 3.0);
    rig
}

#[test]
fn configured_noise_alarms_on_vibration_adaptive_does_not() {
    let x = [0.3, -0.1, 0.2];
    let mut configured = vibrating_rig(ParityNoise::Configured, pyramid4(), 1);
    let alarms = (0..20_000)
        .filter(|_| configured.step(x, false).1.detected_not_isolated)
        .count();
    assert!(
        alarms > 100,
        "configured noise must be overwhelmed: {alarms} alarm samples"
    );

    let mut adaptive = vibrating_rig(ParityNoise::Adaptive, pyramid4(), 1);
    let warmup = adaptive.monitor.settings().learning_samples;
    for k in 0..warmup {
        let (_, st) = adaptive.step(x, false);
        assert!(st.learning, "sample {k}");
        assert!(!st.detected_not_isolated, "no declarations while learning");
    }
    for k in 0..200_000 {
        let (_, st) = adaptive.step(x, false);
        assert!(!st.learning);
        assert!(
            !st.detected_not_isolated,
            "false alarm at {k}, T = {}",
            st.test_statistic
        );
    }
    // The learnt covariance is ≈ 9× the configured one.
    let space = adaptive.monitor.parity().unwrap();
    let cfg_var = space.configured_covariance()[0][0];
    let w = space.whitened_basis();
    let whitened_scale: f64 = (0..4).map(|i| w[0][i] * w[0][i]).sum::<f64>() * cfg_var;
    assert!(
        (1.0 / whitened_scale / 9.0 - 1.0).abs() < 0.1,
        "{}",
        1.0 / whitened_scale
    );
}

/// After learning, a 5σ step (σ of the real parity noise) is still declared within 10 samples,
/// and with six channels isolated; the estimate does not learn the fault.
#[test]
fn adaptive_mode_still_detects_and_isolates() {
    let x = [0.1, 0.2, 0.3];
    let mut rig = vibrating_rig(ParityNoise::Adaptive, pyramid4(), 2);
    for _ in 0..20_000 {
        rig.step(x, false);
    }
    let space = rig.monitor.parity().unwrap();
    let w2: f64 = space.whitened_basis().iter().map(|r| r[1] * r[1]).sum();
    rig.inject(1, Fault::Bias(5.0 / w2.sqrt()));
    let delay = (1..=10).find(|_| rig.step(x, false).1.detected_not_isolated);
    assert!(delay.is_some());
    for _ in 0..20_000 {
        rig.step(x, false);
    }
    assert!(
        rig.monitor.status().detected_not_isolated,
        "the fault was not learnt as noise"
    );

    let mut rig = vibrating_rig(ParityNoise::Adaptive, dodecahedron(), 3);
    for _ in 0..20_000 {
        rig.step(x, false);
    }
    rig.inject(4, Fault::Bias(8.0 * 3.0 * GYRO_SIGMA));
    for _ in 0..50 {
        rig.step(x, false);
    }
    assert_eq!(rig.monitor.exclusion(4), FaultReason::Parity);
    assert_eq!(rig.monitor.active_mask(), 0b10_1111);
    // The learnt excess carries over the reconfiguration: no false alarms on five channels.
    for k in 0..100_000 {
        let (_, st) = rig.step(x, false);
        assert!(!st.detected_not_isolated, "false alarm at {k}");
    }
    assert_eq!(rig.monitor.active_mask(), 0b10_1111);
}
