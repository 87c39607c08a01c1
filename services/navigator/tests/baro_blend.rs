//! Baro height blend against the closed-form response of its critically damped loop.

use nalgebra::Vector3;
use rins_navigator::baro_blend::{BaroBlend, BaroBlendConfig, BaroOutcome};
use rins_navigator::mechanisation::{ImuBias, NominalState, Strapdown, StrapdownConfig};

const TAU: f64 = 5.0;
const IMU_DT_US: u64 = 1000;
const BARO_EVERY: u64 = 20; // 50 Hz

/// Level static vehicle at 100 m whose accelerometer reads `−g − up_bias` on the down axis, blended with a
/// baro that reads `baro_height` from t = 0. Calls `check(t_s, state)` after every baro reading.
fn run(
    seconds: f64,
    up_bias: f64,
    baro_height: f64,
    mut check: impl FnMut(f64, &NominalState),
) -> NominalState {
    let start = NominalState::at_rest(0.8, 0.1, 100.0);
    let mut nav = Strapdown::new(start, ImuBias::default(), StrapdownConfig::default());
    let mut blend = BaroBlend::new(BaroBlendConfig {
        time_constant_s: TAU,
        max_lag_s: 0.5,
    });
    let steps = (seconds * 1e6) as u64 / IMU_DT_US;
    for k in 0..=steps {
        let t_us = k * IMU_DT_US;
        if k > 0 {
            let g = nav.gravity();
            assert!(
                nav.propagate([0.0; 3], [0.0, 0.0, -g - up_bias], 1e-3)
                    .is_applied()
            );
        }
        if k.is_multiple_of(BARO_EVERY) {
            let outcome = blend.apply(nav.state_mut(), t_us, t_us, baro_height, true);
            if k == 0 {
                assert_eq!(outcome, BaroOutcome::Started);
            } else {
                assert!(matches!(outcome, BaroOutcome::Applied { .. }));
            }
            check(t_us as f64 * 1e-6, nav.state());
        }
    }
    *nav.state()
}

#[test]
fn gains_put_a_double_pole_at_minus_one_over_tau() {
    let blend = BaroBlend::new(BaroBlendConfig::default());
    let (kh, kv) = blend.gains();
    assert_eq!((kh, kv), (2.0 / 5.0, 1.0 / 25.0));
    // s² + k_h s + k_v has a zero discriminant and its root at −1/τ.
    assert!((kh * kh - 4.0 * kv).abs() < 1e-15);
}

#[test]
fn height_step_follows_the_critically_damped_response_and_settles_without_error() {
    let step = 10.0;
    let mut worst = 0.0f64;
    let mut largest_overshoot = 0.0f64;
    let end = run(15.0 * TAU, 0.0, 100.0 + step, |t, s| {
        // Residual h_baro − h for a double pole at −1/τ with e(0) = Δ, ė(0) = −2Δ/τ: Δ (1 − t/τ) e^{−t/τ}.
        let residual = 100.0 + step - s.alt;
        let expected = step * (1.0 - t / TAU) * (-t / TAU).exp();
        worst = worst.max((residual - expected).abs());
        largest_overshoot = largest_overshoot.max(-residual);
        if t >= 5.0 * TAU {
            // Converged within a few τ: under 3 % of the step from 5τ on.
            assert!(residual.abs() < 0.03 * step, "{t}: {}", s.alt);
        }
    });
    assert!((largest_overshoot / (step * (-2.0f64).exp()) - 1.0).abs() < 0.02);
    // The 50 Hz discrete loop (k_h Δt = 0.008) stays within 0.3 % of the step of the continuous closed form.
    assert!(
        worst < 0.003 * step,
        "largest deviation from closed form {worst} m"
    );
    assert!(
        (end.alt - 110.0).abs() < 1e-4 * step,
        "steady alt {}",
        end.alt
    );
    assert!(
        end.velocity_ned.z.abs() < 1e-4,
        "steady v_D {}",
        end.velocity_ned.z
    );
}

#[test]
fn constant_vertical_accelerometer_error_leaves_b_tau_squared_height_error() {
    let b = 0.01;
    let end = run(20.0 * TAU, b, 100.0, |_, _| {});
    let height_error = end.alt - 100.0;
    assert!(
        (height_error / (b * TAU * TAU) - 1.0).abs() < 0.01,
        "{height_error}"
    );
    let up_speed = -end.velocity_ned.z;
    assert!(
        (up_speed / (2.0 * b * TAU) - 1.0).abs() < 0.01,
        "{up_speed}"
    );
}

fn climbing_state() -> NominalState {
    let mut s = NominalState::at_rest(0.8, 0.1, 100.0);
    s.velocity_ned = Vector3::new(0.0, 0.0, -2.0);
    s
}

#[test]
fn lagging_reading_is_compared_with_the_height_at_its_own_time() {
    // State at t = 1.0 s: 100 m, climbing 2 m/s. Readings from 0.88 s and 0.9 s carry the true heights
    // then, 99.76 m and 99.8 m, so the innovation is zero although they lag by 0.1 s.
    let mut blend = BaroBlend::new(BaroBlendConfig::default());
    let mut s = climbing_state();
    assert_eq!(
        blend.apply(&mut s, 1_000_000, 880_000, 99.76, true),
        BaroOutcome::Started
    );
    match blend.apply(&mut s, 1_000_000, 900_000, 99.8, true) {
        BaroOutcome::Applied { innovation_m } => {
            assert!(innovation_m.abs() < 1e-9, "{innovation_m}")
        }
        other => panic!("{other:?}"),
    }
    assert!((s.alt - 100.0).abs() < 1e-9);
}

#[test]
fn invalid_stale_and_out_of_order_readings_change_nothing() {
    let mut blend = BaroBlend::new(BaroBlendConfig::default());
    let mut s = climbing_state();
    let before = s;
    assert_eq!(
        blend.apply(&mut s, 0, 0, 120.0, false),
        BaroOutcome::Invalid
    );
    assert_eq!(
        blend.apply(&mut s, 0, 0, f64::NAN, true),
        BaroOutcome::Invalid
    );
    assert_eq!(
        blend.apply(&mut s, 2_000_000, 1_000_000, 120.0, true),
        BaroOutcome::Stale
    );
    assert_eq!(
        blend.apply(&mut s, 2_000_000, 2_600_000, 120.0, true),
        BaroOutcome::Stale
    );
    assert_eq!(blend.last_reading_us(), None);
    assert_eq!(
        blend.apply(&mut s, 2_000_000, 2_000_000, 120.0, true),
        BaroOutcome::Started
    );
    assert_eq!(
        blend.apply(&mut s, 2_000_000, 2_000_000, 120.0, true),
        BaroOutcome::OutOfOrder
    );
    assert_eq!(
        blend.apply(&mut s, 2_000_000, 1_990_000, 120.0, true),
        BaroOutcome::OutOfOrder
    );
    assert_eq!(s, before);
}

#[test]
fn a_long_gap_is_capped_at_a_quarter_time_constant() {
    let mut blend = BaroBlend::new(BaroBlendConfig {
        time_constant_s: 4.0,
        max_lag_s: 1.0,
    });
    let mut s = NominalState::at_rest(0.0, 0.0, 0.0);
    let _ = blend.apply(&mut s, 0, 0, 0.0, true);
    // 60 s later, a 10 m innovation: Δt counts as τ/4 = 1 s, so h += (2/τ)·10·1 = 5 m, v_D −= (1/τ²)·10·1.
    let _ = blend.apply(&mut s, 60_000_000, 60_000_000, 10.0, true);
    assert!((s.alt - 5.0).abs() < 1e-12);
    assert!((s.velocity_ned.z + 10.0 / 16.0).abs() < 1e-12);
}
