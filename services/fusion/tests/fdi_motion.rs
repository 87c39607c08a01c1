//! Motion-dependent parity noise: channels that disagree in proportion to the motion (scale
//! factor, misalignment, sampling instants) do not raise alarms in fast manoeuvres when the
//! configuration declares that disagreement, and still do when it does not.

mod common;

use common::{Fault, GYRO_SIGMA, Rig};
use ipc_types::{ChannelState, SensorType};
use rins_fusion::fdi::FdiConfig;

/// The seed pyramid's gyros with exact (unquantised) values.
fn pyramid_gyros(config: &FdiConfig, seed: u64) -> Rig {
    Rig::builder(SensorType::Gyro)
        .exact()
        .config(config)
        .seed(seed)
        .build()
}

/// Alarmed samples over 2 s of a rate of magnitude `rate` rad/s whose direction sweeps (a
/// constant one would be learnt as a parity offset), channel 0 reading 2 % high.
fn alarms_in_a_fast_turn(config: &FdiConfig, rate: f64) -> usize {
    let mut rig = pyramid_gyros(config, 7);
    rig.learn([0.0; 3], false);
    rig.inject(0, Fault::Scale(0.05));
    (0..2000)
        .map(|k| {
            let a = k as f64 * 0.003;
            let x = [
                rate * 0.6 * a.cos(),
                rate * 0.6 * a.sin(),
                rate * 0.8 * (2.0 * a).cos(),
            ];
            rig.step(x, false).1
        })
        .filter(|st| st.detected_not_isolated || st.test_statistic > st.threshold)
        .count()
}

#[test]
fn declared_scale_disagreement_keeps_a_fast_turn_quiet() {
    // 5 % of up to 5 rad/s on one channel: up to 0.25 rad/s, 45 σ of the channel noise; the
    // pyramid's parity sees half of it.
    let plain = FdiConfig::default();
    let n = alarms_in_a_fast_turn(&plain, 5.0);
    assert!(n > 100, "{n}");
    let declared = FdiConfig {
        motion_noise_fraction: 0.06,
        ..FdiConfig::default()
    };
    assert_eq!(alarms_in_a_fast_turn(&declared, 5.0), 0);
}

#[test]
fn declared_disagreement_still_leaves_a_bias_visible_at_rest() {
    // At rest the motion term is zero: a 9σ bias is detected as without it.
    let declared = FdiConfig {
        motion_noise_fraction: 0.03,
        timing_skew_s: 0.006,
        ..FdiConfig::default()
    };
    let mut rig = pyramid_gyros(&declared, 3);
    rig.learn([0.0; 3], false);
    rig.inject(1, Fault::Bias(9.0 * GYRO_SIGMA));
    let detected = (1..=10).any(|_| rig.step([0.0; 3], false).1.detected_not_isolated);
    assert!(detected);
}

#[test]
fn out_of_range_motion_settings_are_refused() {
    for (f, tau) in [
        (-0.1, 0.0),
        (1.0, 0.0),
        (f64::NAN, 0.0),
        (0.0, -1.0),
        (0.0, 2.0),
    ] {
        let cfg = FdiConfig {
            motion_noise_fraction: f,
            timing_skew_s: tau,
            ..FdiConfig::default()
        };
        let e = cfg.settings().expect_err("refused").to_string();
        assert!(
            e.contains("motion_noise_fraction") || e.contains("timing_skew_s"),
            "{e}"
        );
    }
}

/// A rate of magnitude `rate` rad/s at step `k` whose direction sweeps the sphere.
fn sweeping(rate: f64, k: usize) -> [f64; 3] {
    let a = k as f64 * 0.003;
    [
        rate * 0.6 * a.cos(),
        rate * 0.6 * a.sin(),
        rate * 0.8 * (2.0 * a).cos(),
    ]
}

/// Channel 0 reads 3 % high from the start. After the learning phase at rest, 20 s of gentle
/// manoeuvring (0.4 rad/s: the error stays near the noise), then 2 s of a fast turn (5 rad/s).
/// Returns the alarmed samples of the gentle part and of the turn.
fn alarms_after_gentle_flight(config: &FdiConfig) -> (usize, usize) {
    let mut rig = pyramid_gyros(config, 11);
    rig.inject(0, Fault::Scale(0.03));
    rig.learn([0.0; 3], false);
    let alarms = |rig: &mut Rig, rate: f64, samples: usize| {
        (0..samples)
            .map(|k| rig.step(sweeping(rate, k), false).1)
            .filter(|st| st.detected_not_isolated || st.test_statistic > st.threshold)
            .count()
    };
    let gentle = alarms(&mut rig, 0.4, 20_000);
    let turn = alarms(&mut rig, 5.0, 2_000);
    (gentle, turn)
}

#[test]
fn a_learnt_relative_scale_error_keeps_a_fast_turn_quiet() {
    // 3 % of 5 rad/s on one channel is 0.15 rad/s, 27 σ; no motion noise is declared here.
    let (gentle_plain, plain) = alarms_after_gentle_flight(&FdiConfig::default());
    assert!(plain > 100, "{plain}");
    let learnt = FdiConfig {
        motion_offset: true,
        ..FdiConfig::default()
    };
    // The gentle part exceeds while the slope is learnt (its first seconds), ten times less than
    // without; the turn then raises nothing.
    let (gentle, turn) = alarms_after_gentle_flight(&learnt);
    assert!(
        gentle * 10 < gentle_plain,
        "{gentle} against {gentle_plain}"
    );
    assert_eq!(turn, 0);
}

#[test]
fn the_motion_offset_still_detects_a_bias_at_once() {
    let learnt = FdiConfig {
        motion_offset: true,
        ..FdiConfig::default()
    };
    let mut rig = pyramid_gyros(&learnt, 5);
    // Learnt where the sweep starts: a step from rest to 1 rad/s would read as channel noise.
    rig.learn(sweeping(1.0, 0), false);
    for k in 0..5_000 {
        let st = rig.step(sweeping(1.0, k), false).1;
        assert!(!st.detected_not_isolated && !st.states.contains(&ChannelState::Excluded));
    }
    // Four channels detect a fault but cannot tell which (one parity dimension).
    rig.inject(2, Fault::Bias(9.0 * GYRO_SIGMA));
    let detected =
        (5_000..5_010).any(|k| rig.step(sweeping(1.0, k), false).1.detected_not_isolated);
    assert!(detected);
}

#[test]
fn the_motion_offset_needs_the_parity_offset() {
    let cfg = FdiConfig {
        motion_offset: true,
        parity_offset_window: 0,
        ..FdiConfig::default()
    };
    let e = cfg.settings().expect_err("refused").to_string();
    assert!(e.contains("motion_offset"), "{e}");
}
