//! Per-channel gyro biases from the start-up window at rest: subtracted channel by channel, so a
//! later exclusion does not step the fused rate by the remaining channels' projected biases.

mod fuser_block;

use fuser_block::{ALL_VALID, AT_REST_FORCE, Block, GYRO_LSB};
use rins_fusion::config::default_gyro_sigma_rps;
use rins_fusion::{Fused, FusionConfig, FusionMethod, RestBiasState, WlsSolver};

/// Distinct turn-on biases, rad/s (about 1–2 channel σ): a part along the parity direction, which
/// the full set hides and a 3-channel set does not, and a part the full set sees as body-axis bias.
const BIASES: [f64; 4] = [0.012, -0.006, 0.009, -0.004];
const EXCLUDE_AT: usize = 3_000;
/// Samples averaged on each side of the exclusion.
const SIDE: usize = 100;
const ZERO: [f64; 3] = [0.0; 3];
/// Gyro channel that drops out.
const DROPPED: u32 = 0b0100;

fn channel_variance() -> f64 {
    default_gyro_sigma_rps().powi(2) + GYRO_LSB * GYRO_LSB / 12.0
}

/// The block at rest with the biases; gyro channel 2 drops out at `EXCLUDE_AT`.
fn run(cfg: &FusionConfig, seed: u64) -> (Block, Vec<Fused>) {
    let mut block = Block::new(cfg, seed);
    block.gyro_bias = BIASES;
    let frames = (0..EXCLUDE_AT + SIDE)
        .map(|k| {
            let valid = if k < EXCLUDE_AT {
                ALL_VALID
            } else {
                ALL_VALID & !DROPPED
            };
            block.step(ZERO, AT_REST_FORCE, valid)
        })
        .collect();
    (block, frames)
}

fn mean(frames: &[Fused]) -> [f64; 3] {
    fuser_block::mean_rate(frames)
}

/// Step of the mean fused rate across the exclusion, and its noise-only σ per axis: the means of
/// two independent runs of `SIDE` samples (4 then 3 channels), plus the bias estimate's own error
/// (σ²/W per channel) projected through the difference of the two solvers.
fn step_and_sigma(block: &Block, frames: &[Fused], window: usize) -> ([f64; 3], [f64; 3]) {
    let before = mean(&frames[EXCLUDE_AT - SIDE..EXCLUDE_AT]);
    let after = mean(&frames[EXCLUDE_AT..]);
    let v = channel_variance();
    let full = WlsSolver::new(&block.gyro, 0b1111, &[v; 4]).unwrap();
    let three = WlsSolver::new(&block.gyro, 0b1111 & !DROPPED, &[v; 4]).unwrap();
    let (c4, c3) = (full.covariance(), three.covariance());
    let estimate_var = if window > 0 { v / window as f64 } else { 0.0 };
    let sigma = std::array::from_fn(|a| {
        // (G3 − G4) e for the estimate error e: variance Σ_i (G3 − G4)_ai² σ²/W.
        let unit = |i: usize| {
            let mut z = [0.0; 4];
            z[i] = 1.0;
            three.solve(&z).0[a] - full.solve(&z).0[a]
        };
        let projected: f64 = (0..4).map(|i| unit(i).powi(2) * estimate_var).sum();
        ((c4[a][a] + c3[a][a]) / SIDE as f64 + projected).sqrt()
    });
    (std::array::from_fn(|a| after[a] - before[a]), sigma)
}

#[test]
fn rest_bias_removes_the_step_at_an_exclusion() {
    let cfg = FusionConfig::default();
    let window = cfg.rest_bias_samples().unwrap() as usize;
    assert_eq!(window, 1000, "1 s at 1 kHz by default");
    let (block, frames) = run(&cfg, 3);
    assert!(block.fuser.rest_bias_estimated());
    assert_eq!(block.fuser.rest_bias_state(), RestBiasState::Estimated);
    // Each channel's mean over the window: bias + σ/√W noise (quantisation dithered by the noise).
    let sd = (channel_variance() / window as f64).sqrt();
    for (i, (b, truth)) in block.fuser.gyro_rest_bias().iter().zip(BIASES).enumerate() {
        assert!((b - truth).abs() < 4.5 * sd, "channel {i}: {b} vs {truth}");
    }
    // No parity alarm when the biases start to be subtracted (the learnt offset moves with them).
    assert!(frames.iter().all(|f| !f.gyro_status.detected_not_isolated));
    assert_eq!(frames[EXCLUDE_AT].gyro_mask, 0b1011);
    // After the window the fused rate at rest is ≈ 0: nothing left for the navigator's bias.
    let settled = mean(&frames[window..EXCLUDE_AT]);
    let n = (EXCLUDE_AT - window) as f64;
    for (a, m) in settled.iter().enumerate() {
        let var = frames[window].rate_var[a];
        assert!(
            m.abs() < 4.5 * (var / n + var / window as f64).sqrt(),
            "axis {a}: {settled:?}"
        );
    }
    let (step, sigma) = step_and_sigma(&block, &frames, window);
    for a in 0..3 {
        assert!(
            step[a].abs() < 4.5 * sigma[a],
            "axis {a}: step {step:?}, σ {sigma:?}"
        );
    }
}

#[test]
fn without_rest_bias_an_exclusion_steps_by_the_projected_bias_difference() {
    let cfg = FusionConfig {
        rest_bias_s: 0.0,
        ..FusionConfig::default()
    };
    let (block, frames) = run(&cfg, 3);
    assert_eq!(block.fuser.rest_bias_state(), RestBiasState::Disabled);
    assert!(block.fuser.gyro_rest_bias().iter().all(|b| *b == 0.0));
    assert!(frames.iter().all(|f| !f.gyro_status.detected_not_isolated));
    let v = channel_variance();
    let full = WlsSolver::new(&block.gyro, 0b1111, &[v; 4]).unwrap();
    let three = WlsSolver::new(&block.gyro, 0b1011, &[v; 4]).unwrap();
    let mut b = [0.0; 4];
    b.copy_from_slice(&BIASES);
    let expected: [f64; 3] = std::array::from_fn(|a| three.solve(&b).0[a] - full.solve(&b).0[a]);
    let (step, sigma) = step_and_sigma(&block, &frames, 0);
    for a in 0..3 {
        assert!(
            (step[a] - expected[a]).abs() < 4.5 * sigma[a],
            "axis {a}: step {step:?} vs (G3 − G4) b = {expected:?}, σ {sigma:?}"
        );
    }
    // The step is well outside the noise: the test above can tell the two apart.
    let size: f64 = (0..3)
        .map(|a| (expected[a] / sigma[a]).powi(2))
        .sum::<f64>()
        .sqrt();
    assert!(size > 20.0, "step of {size} σ");
}

#[test]
fn a_window_in_motion_estimates_nothing() {
    // A steady turn: no spread, but a mean rate above the stationary limit.
    let mut block = Block::new(&FusionConfig::default(), 5);
    block.gyro_bias = BIASES;
    let turn = [0.0, 0.0, 0.3];
    let frames: Vec<Fused> = (0..1500)
        .map(|_| block.step(turn, AT_REST_FORCE, ALL_VALID))
        .collect();
    assert_eq!(block.fuser.rest_bias_state(), RestBiasState::NotAtRest);
    assert!(!block.fuser.rest_bias_estimated());
    assert!(block.fuser.gyro_rest_bias().iter().all(|b| *b == 0.0));
    // Nothing subtracted: the mean after the window is the turn plus the full set's body bias.
    let v = channel_variance();
    let full = WlsSolver::new(&block.gyro, 0b1111, &[v; 4]).unwrap();
    let body_bias = full.solve(&BIASES).0;
    let m = mean(&frames[1000..]);
    for a in 0..3 {
        let sd = (frames[1000].rate_var[a] / 500.0).sqrt();
        assert!(
            (m[a] - turn[a] - body_bias[a]).abs() < 4.5 * sd,
            "axis {a}: {m:?}"
        );
    }
}

#[test]
fn rest_bias_works_with_the_kalman_method() {
    let cfg = FusionConfig {
        method: FusionMethod::Kalman,
        ..FusionConfig::default()
    };
    let (block, frames) = run(&cfg, 8);
    assert!(block.fuser.rest_bias_estimated());
    assert_eq!(block.fuser.method(), FusionMethod::Kalman);
    let (step, sigma) = step_and_sigma(&block, &frames, 1000);
    // The filtered output is smoother than WLS, so the WLS-based σ is a conservative bound.
    for a in 0..3 {
        assert!(
            step[a].abs() < 4.5 * sigma[a],
            "axis {a}: step {step:?}, σ {sigma:?}"
        );
    }
}
