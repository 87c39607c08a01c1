//! Recovery of a sensor type that lost its solution, and the saturated block: every channel
//! invalid for a while (a connector, a bus reset) must not leave the type out for good; a block
//! reading full scale on every channel is not motion.

mod common;

use common::{Fault, GYRO_SIGMA, Rig};
use ipc_types::{ChannelState, FaultReason, SensorType};
use rins_fusion::fdi::{FdiConfig, ReadmitPolicy};

const X: [f64; 3] = [0.2, 0.1, -0.3];

fn gyro_rig(cfg: &FdiConfig) -> Rig {
    Rig::builder(SensorType::Gyro).config(cfg).seed(7).build()
}

/// Every channel dead for `samples`, then back.
fn all_dead_then_back(rig: &mut Rig, samples: u32) {
    for ch in 0..4 {
        rig.inject(ch, Fault::Dead);
    }
    for _ in 0..samples {
        let (est, st) = rig.step(X, false);
        assert!(!est.ok);
        assert_eq!(st.mask_of(ChannelState::Excluded), 0b1111);
    }
    for ch in 0..4 {
        rig.inject(ch, Fault::None);
    }
}

#[test]
fn a_type_that_lost_every_channel_readmits_them_once_consistent_for_the_hold() {
    let cfg = FdiConfig::default();
    let hold = cfg.readmit_after_samples;
    let mut rig = gyro_rig(&cfg);
    for _ in 0..100 {
        rig.step(X, false);
    }
    all_dead_then_back(&mut rig, 500);
    // Valid again: out for exactly the hold, then all four return together, with an event each.
    for k in 1..hold {
        let (est, st) = rig.step(X, false);
        assert!(!est.ok, "sample {k} of the hold");
        assert_eq!(st.auto_readmitted, 0);
    }
    let (est, st) = rig.step(X, false);
    assert!(est.ok);
    assert_eq!(est.mask, 0b1111);
    assert_eq!(st.auto_readmitted, 0b1111);
    assert_eq!(st.mask_of(ChannelState::Ok), 0b1111);
    let back: Vec<_> = rig
        .events
        .as_slice()
        .iter()
        .map(|e| (e.channel, e.old_state, e.new_state, e.old_reason))
        .collect();
    assert_eq!(
        back,
        (0..4)
            .map(|ch| (
                ch,
                ChannelState::Excluded,
                ChannelState::Ok,
                FaultReason::Missing
            ))
            .collect::<Vec<_>>()
    );
    // The solution is the fault-free one again: within 5σ of the true rate on every axis.
    for (e, x) in est.x.iter().zip(X) {
        assert!((e - x).abs() < 5.0 * GYRO_SIGMA, "{:?} vs {X:?}", est.x);
    }
}

#[test]
fn with_the_operator_policy_the_exclusions_stay_latched() {
    let cfg = FdiConfig {
        readmit: ReadmitPolicy::Operator,
        ..FdiConfig::default()
    };
    let mut rig = gyro_rig(&cfg);
    all_dead_then_back(&mut rig, 50);
    for _ in 0..3 * cfg.readmit_after_samples {
        let (est, _) = rig.step(X, false);
        assert!(!est.ok);
    }
    assert_eq!(rig.monitor.readmit(1), Ok(true));
}

#[test]
fn a_type_that_still_has_a_solution_keeps_its_exclusion_latched() {
    let cfg = FdiConfig::default();
    let mut rig = gyro_rig(&cfg);
    rig.inject(2, Fault::Dead);
    rig.step(X, false);
    rig.inject(2, Fault::None);
    for _ in 0..3 * cfg.readmit_after_samples {
        let (est, st) = rig.step(X, false);
        assert!(est.ok);
        assert_eq!(st.states[2], ChannelState::Excluded);
    }
}

#[test]
fn a_channel_that_disagrees_does_not_come_back_with_the_others() {
    let cfg = FdiConfig::default();
    let mut rig = gyro_rig(&cfg);
    all_dead_then_back(&mut rig, 50);
    // Channel 3 returns biased by 100σ: its parity with the other three exceeds the threshold on
    // every sample, so nobody returns (with four candidates the set is judged as a whole) …
    rig.inject(3, Fault::Bias(100.0 * GYRO_SIGMA));
    for _ in 0..3 * cfg.readmit_after_samples {
        let (est, _) = rig.step(X, false);
        assert!(!est.ok);
    }
    // … until it is flagged invalid: then the three consistent ones return on their own.
    rig.inject(3, Fault::Dead);
    let mut back_after = None;
    for k in 1..=cfg.readmit_after_samples + 1 {
        let (est, st) = rig.step(X, false);
        if est.ok {
            back_after = Some(k);
            assert_eq!(st.auto_readmitted, 0b0111);
            break;
        }
    }
    assert_eq!(back_after, Some(cfg.readmit_after_samples));
}

#[test]
fn a_block_at_full_scale_is_flagged_saturated_and_nothing_is_excluded() {
    let cfg = FdiConfig::default();
    let mut rig = gyro_rig(&cfg);
    for _ in 0..100 {
        rig.step(X, false);
    }
    for ch in 0..4 {
        rig.inject(ch, Fault::Rail);
    }
    for _ in 0..3000 {
        let (_, st) = rig.step(X, false);
        assert!(st.block_saturated);
        assert_eq!(st.mask_of(ChannelState::Excluded), 0);
    }
    for ch in 0..4 {
        rig.inject(ch, Fault::None);
    }
    let (est, st) = rig.step(X, false);
    assert!(!st.block_saturated && est.ok);
    assert_eq!(st.mask_of(ChannelState::Ok), 0b1111);
    // Two channels at the rail leave two off it: too few to solve, still saturated.
    rig.inject(0, Fault::Rail);
    rig.inject(1, Fault::Rail);
    let (_, st) = rig.step(X, false);
    assert!(st.block_saturated);
    // One channel at the rail leaves three off it: the block can be solved.
    rig.inject(1, Fault::None);
    let (_, st) = rig.step(X, false);
    assert!(!st.block_saturated);
}
