//! Channel-health isolation: missing, stuck, saturated and noisy channels, within their sample
//! budgets, and the readmit command.

mod common;

use common::{
    ACCEL_LSB, ACCEL_SIGMA, Fault, GYRO_LSB, GYRO_SIGMA, Rig, dodecahedron, pyramid4, random_vector,
};
use ipc_types::{ChannelState, FaultReason, SensorType};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rins_fusion::fdi::FdiConfig;
use rins_fusion::fdi::channel_health::COUNT_MAX;

/// Steps until `channel` is excluded; returns (samples since the fault started, reason).
fn until_excluded(
    rig: &mut Rig,
    channel: usize,
    x: impl Fn(u32) -> [f64; 3],
    limit: u32,
) -> (u32, FaultReason) {
    for t in 1..=limit {
        rig.step(x(t), false);
        let r = rig.monitor.exclusion(channel);
        if r != FaultReason::None {
            return (t, r);
        }
    }
    panic!("channel {channel} not excluded within {limit} samples");
}

#[test]
fn missing_channel_is_excluded_on_the_same_sample_and_stays_out() {
    let cfg = FdiConfig::default();
    let mut rig = Rig::builder(SensorType::Gyro).config(&cfg).seed(1).build();
    let x = [0.2, 0.1, -0.3];
    for _ in 0..10 {
        rig.step(x, false);
    }
    rig.inject(2, Fault::Dead);
    let (est, st) = rig.step(x, false);
    assert_eq!(
        (st.states[2], st.reasons[2]),
        (ChannelState::Excluded, FaultReason::Missing)
    );
    assert_eq!(est.mask, 0b1011);
    assert!(est.ok);
    let ev = rig.events.as_slice();
    assert_eq!(ev.len(), 1);
    assert_eq!(
        (ev[0].channel, ev[0].old_state, ev[0].new_state),
        (2, ChannelState::Ok, ChannelState::Excluded)
    );
    assert_eq!(
        (ev[0].sensor, ev[0].reason),
        (SensorType::Gyro, FaultReason::Missing)
    );
    // The channel comes back valid: it stays excluded (latched), no further events.
    rig.inject(2, Fault::None);
    for _ in 0..100 {
        let (est, st) = rig.step(x, false);
        assert_eq!(st.states[2], ChannelState::Excluded);
        assert_eq!(est.mask, 0b1011);
        assert!(rig.events.is_empty());
    }
    // Below three channels the solution is invalid.
    rig.inject(0, Fault::Dead);
    let (est, st) = rig.step(x, false);
    assert!(!est.ok);
    assert_eq!(est.x, [0.0; 3]);
    assert_eq!(st.parity_dimension, 0);
}

/// A frozen channel on a moving signal is excluded (Stuck) within 20 samples, for both sensor
/// types, over many random trials; the sample budget is spent by the run length (19 frozen samples
/// plus the last good one).
#[test]
fn stuck_channel_is_excluded_within_twenty_samples() {
    let cfg = FdiConfig::default();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for (sensor, sigma, lsb) in [
        (SensorType::Gyro, GYRO_SIGMA, GYRO_LSB),
        (SensorType::Accel, ACCEL_SIGMA, ACCEL_LSB),
    ] {
        for trial in 0..200 {
            let mut rig = Rig::builder(sensor)
                .sigma(sigma)
                .lsb(lsb)
                .config(&cfg)
                .seed(300 + trial)
                .build();
            let x = random_vector(&mut rng, 20.0 * sigma);
            for _ in 0..rng.random_range(30..60) {
                rig.step(x, false);
            }
            let channel = rng.random_range(0..4);
            rig.inject(channel, Fault::Stuck);
            let (t, reason) = until_excluded(&mut rig, channel, |_| x, 40);
            assert_eq!(reason, FaultReason::Stuck, "{sensor:?} trial {trial}");
            assert!(t <= 20, "{sensor:?} trial {trial}: {t} samples");
            assert_eq!(rig.monitor.active_mask().count_ones(), 3);
        }
    }
}

/// Numerical check of the false-alarm table in `channel_health`: Σ_k p_k^L for quantised
/// Gaussian noise on a count, and the resulting expected alarms per hour with 4 channels.
#[test]
fn stuck_false_alarm_arithmetic() {
    fn phi(x: f64) -> f64 {
        // Φ by Simpson integration of the density from 0 (accurate to 1e-12 here).
        let steps = 2000;
        let h = x / steps as f64;
        let f = |t: f64| (-0.5 * t * t).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let mut s = f(0.0) + f(x);
        for i in 1..steps {
            s += f(i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        0.5 + s * h / 3.0
    }
    let run_probability = |sigma: f64, l: i32| -> f64 {
        (-30..=30)
            .map(|k: i32| {
                let k = f64::from(k);
                phi((k + 0.5) / sigma) - phi((k - 0.5) / sigma)
            })
            .map(|p| p.powi(l))
            .sum()
    };
    let per_hour = |sigma: f64, l: i32| 3.6e6 * 4.0 * run_probability(sigma, l);
    let l = FdiConfig::default().stuck_samples as i32;
    assert_eq!(l, 20);
    assert!((run_probability(1.2, 15) / 4.4e-8 - 1.0).abs() < 0.02);
    assert!(per_hour(1.2, 15) > 0.5, "the brief's 15 would not do");
    assert!(
        per_hour(1.2, 19) < 0.01 && per_hour(1.2, 18) > 0.01,
        "19 is the smallest that does"
    );
    assert!((per_hour(1.2, l) - 0.0022).abs() < 0.0001);
    assert!(per_hour(2.2, l) < 1e-7);
}

/// A channel pinned at the rail while the others place it mid-range is excluded (Saturated)
/// within 20 samples; with N = 6 parity may get there first — either way within 20.
#[test]
fn saturated_channel_is_excluded_within_twenty_samples() {
    let cfg = FdiConfig::default();
    for (geometry, seed) in [(pyramid4(), 4), (dodecahedron(), 5)] {
        let mut rig = Rig::builder(SensorType::Accel)
            .geometry(geometry)
            .config(&cfg)
            .seed(seed)
            .build();
        let x = [0.3, -0.5, -9.8];
        for _ in 0..50 {
            rig.step(x, false);
        }
        rig.inject(1, Fault::Rail);
        let (t, reason) = until_excluded(&mut rig, 1, |_| x, 40);
        assert!(t <= 20, "{t}");
        if geometry.n() == 4 {
            assert_eq!((t, reason), (5, FaultReason::Saturated));
        } else {
            assert!(matches!(
                reason,
                FaultReason::Saturated | FaultReason::Parity
            ));
        }
    }
}

/// A genuine over-range (the motion exceeds full scale along one channel's axis) is not a
/// fault: the channel is Suspect while it sits on the rail and Ok afterwards, never excluded.
#[test]
fn genuine_over_range_is_suspect_not_excluded() {
    let cfg = FdiConfig::default();
    let g = pyramid4();
    let mut rig = Rig::builder(SensorType::Gyro)
        .geometry(g)
        .config(&cfg)
        .seed(6)
        .build();
    let full_scale = f64::from(COUNT_MAX) * GYRO_LSB;
    let h0 = g.axes()[0];
    let over = h0.map(|c| c * 1.2 * full_scale);
    for _ in 0..20 {
        rig.step([0.0; 3], false);
    }
    let mut suspect = false;
    for _ in 0..50 {
        let (_, st) = rig.step(over, false);
        suspect |= st.states[0] == ChannelState::Suspect && st.reasons[0] != FaultReason::None;
        assert_ne!(st.states[0], ChannelState::Excluded);
    }
    assert!(suspect);
    for _ in 0..20 {
        rig.step([0.0; 3], false);
    }
    let (_, st) = rig.step([0.0; 3], false);
    assert_eq!(rig.monitor.active_mask(), 0b1111);
    assert!(st.states[..4].iter().all(|s| *s == ChannelState::Ok));
}

/// Noise ×10 (variance ×100 > 25 × the others') is excluded (Noisy) within two noise windows;
/// noise ×3 (variance ×9) is not.
#[test]
fn noisy_channel_is_excluded_within_two_windows() {
    let cfg = FdiConfig::default();
    let window = cfg.noise_window;
    let mut rig = Rig::builder(SensorType::Gyro).config(&cfg).seed(7).build();
    let x = [0.1, 0.2, 0.3];
    for _ in 0..137 {
        rig.step(x, false);
    }
    rig.inject(3, Fault::Noise(10.0));
    let (t, reason) = until_excluded(&mut rig, 3, |_| x, 2 * window);
    assert_eq!(reason, FaultReason::Noisy);
    assert!(t <= 2 * window, "{t}");

    let mut rig = Rig::builder(SensorType::Gyro)
        .geometry(dodecahedron())
        .config(&cfg)
        .seed(8)
        .build();
    rig.inject(3, Fault::Noise(3.0));
    for _ in 0..10 * window {
        rig.step(x, false);
    }
    // ×3 noise is left to parity (which, with six channels, may well isolate it).
    assert_ne!(rig.monitor.exclusion(3), FaultReason::Noisy);
}

/// With three channels left a noisy one is only Suspect: excluding it would end the solution.
#[test]
fn noisy_channel_among_three_is_suspect() {
    let cfg = FdiConfig::default();
    let mut rig = Rig::builder(SensorType::Gyro).config(&cfg).seed(9).build();
    rig.inject(0, Fault::Dead);
    rig.inject(2, Fault::Noise(10.0));
    let x = [0.1, 0.2, 0.3];
    let mut last = None;
    for _ in 0..2 * cfg.noise_window {
        last = Some(rig.step(x, false));
    }
    let (est, st) = last.unwrap();
    assert!(est.ok);
    assert_eq!(est.mask, 0b1110);
    assert_eq!(
        (st.states[2], st.reasons[2]),
        (ChannelState::Suspect, FaultReason::Noisy)
    );
}

/// Readmit puts an excluded channel on probation, out of the solution; still faulty, it stays
/// excluded; repaired, it returns at the probation's end (event Excluded → Ok). Unknown channels
/// are refused.
#[test]
fn readmit_is_explicit_and_the_channel_is_judged_again() {
    let cfg = FdiConfig::default();
    let mut rig = Rig::builder(SensorType::Gyro).config(&cfg).seed(10).build();
    let x = [0.4, 0.1, 0.2];
    rig.inject(1, Fault::Dead);
    rig.step(x, false);
    assert_eq!(rig.monitor.active_mask(), 0b1101);
    assert_eq!(rig.monitor.readmit(0), Ok(false));
    assert!(rig.monitor.readmit(4).is_err());
    assert_eq!(
        rig.monitor.readmit(9).unwrap_err().to_string(),
        "gyro channel 9 does not exist (4 channels fitted)"
    );
    // Still dead: on probation out of the solution, refused on the next sample (no event: the
    // state is Excluded/Missing before and after the sample).
    assert_eq!(rig.monitor.readmit(1), Ok(true));
    assert_eq!(rig.monitor.active_mask(), 0b1101);
    assert!(rig.monitor.on_probation(1));
    rig.step(x, false);
    assert!(!rig.monitor.on_probation(1));
    assert_eq!(rig.monitor.active_mask(), 0b1101);
    assert!(rig.events.is_empty());
    // Repaired: readmitted, out for the probation, then in.
    rig.inject(1, Fault::None);
    assert_eq!(rig.monitor.readmit(1), Ok(true));
    for _ in 1..cfg.readmit_probation_samples {
        let (est, st) = rig.step(x, false);
        assert_eq!(est.mask, 0b1101);
        assert_eq!(st.states[1], ChannelState::Excluded);
    }
    let (est, st) = rig.step(x, false);
    assert_eq!(est.mask, 0b1111);
    assert_eq!(st.states[1], ChannelState::Ok);
    let ev = rig.events.as_slice();
    assert_eq!(ev.len(), 1);
    assert_eq!(
        (
            ev[0].old_state,
            ev[0].new_state,
            ev[0].old_reason,
            ev[0].reason
        ),
        (
            ChannelState::Excluded,
            ChannelState::Ok,
            FaultReason::Missing,
            FaultReason::None
        )
    );
    for _ in 0..1000 {
        rig.step(x, false);
    }
    assert_eq!(rig.monitor.active_mask(), 0b1111);
}
