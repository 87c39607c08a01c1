//! Strapdown mechanisation against closed-form motions.

mod common;

use std::f64::consts::PI;

use nalgebra::{UnitQuaternion, Vector3};
use proptest::prelude::*;
use rins_earth::{meridian_radius, prime_vertical_radius};
use rins_navigator::attitude::{rotation_vector_to_quaternion, wrap_pi};
use rins_navigator::mechanisation::{
    ImuBias, NominalState, StepOutcome, Strapdown, StrapdownConfig, euler_from_quaternion,
    quaternion_from_euler,
};

fn strapdown(state: NominalState, coning: bool) -> Strapdown {
    Strapdown::new(
        state,
        ImuBias::default(),
        StrapdownConfig {
            max_dt_s: 0.1,
            coning_correction: coning,
        },
    )
}

fn at_45_deg() -> NominalState {
    NominalState::at_rest(45f64.to_radians(), 10f64.to_radians(), 100.0)
}

#[test]
fn constant_rate_about_fixed_axis_matches_closed_form_exponential() {
    let q0 = quaternion_from_euler(0.2, -0.3, 1.0);
    let rate = Vector3::new(0.3, -0.2, 0.5);
    let (dt, steps) = (1e-3, 10_000);
    for coning in [false, true] {
        let mut state = at_45_deg();
        state.attitude = q0;
        let mut nav = strapdown(state, coning);
        for _ in 0..steps {
            let g = nav.gravity();
            assert!(nav.propagate(rate.into(), [0.0, 0.0, -g], dt).is_applied());
        }
        let expected = q0 * rotation_vector_to_quaternion(&(rate * (dt * steps as f64)));
        let error = nav.state().attitude.angle_to(&expected);
        assert!(error < 1e-9, "coning {coning}: error {error} rad");
    }
}

/// Closed-form attitude `q(t) = q_z(a t) ⊗ q_x(b t)`: a spin about the NED down axis and a spin about body x.
/// Its body rate is `ω(t) = [b, a sin bt, a cos bt]`, an axis that sweeps a cone at rate b.
fn cone_attitude(a: f64, b: f64, t: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a * t)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), b * t)
}

/// Mean body rate of [`cone_attitude`] over `[t0, t1]` (what an integrating sensor reports).
fn cone_mean_rate(a: f64, b: f64, t0: f64, t1: f64) -> [f64; 3] {
    let span = b * (t1 - t0);
    [
        b,
        a * ((b * t0).cos() - (b * t1).cos()) / span,
        a * ((b * t1).sin() - (b * t0).sin()) / span,
    ]
}

/// Cone used by the varying-axis test: 1 rad/s about down, 1 Hz about body x, for 10 s.
const CONE_A: f64 = 1.0;
const CONE_B: f64 = 2.0 * PI;
const CONE_SECONDS: f64 = 10.0;

fn cone_error(coning: bool, rate_hz: f64) -> f64 {
    let (a, b, duration) = (CONE_A, CONE_B, CONE_SECONDS);
    let dt = 1.0 / rate_hz;
    let steps = (duration * rate_hz).round() as usize;
    let mut nav = strapdown(at_45_deg(), coning);
    for k in 0..steps {
        let (t0, t1) = (k as f64 * dt, (k + 1) as f64 * dt);
        let g = nav.gravity();
        let _ = nav.propagate(cone_mean_rate(a, b, t0, t1), [0.0, 0.0, -g], dt);
    }
    nav.state()
        .attitude
        .angle_to(&cone_attitude(a, b, steps as f64 * dt))
}

#[test]
fn varying_axis_motion_tracks_closed_form_and_coning_term_helps() {
    let (a, b, duration) = (CONE_A, CONE_B, CONE_SECONDS);
    // Without the correction each step misses the coning term (dt³/12) ω×ω̇ of the rotation vector. Its
    // component a b² is fixed in the frame of the z spin, so it accumulates to a b² T dt² / 12 (second
    // order); the two-sample term cancels it, leaving a third-order error.
    let plain = cone_error(false, 100.0);
    let dt = 1e-2;
    let predicted = a * b * b * duration * dt * dt / 12.0;
    assert!(
        (plain / predicted - 1.0).abs() < 0.05,
        "uncorrected {plain} vs {predicted}"
    );
    let plain_order = plain / cone_error(false, 200.0);
    assert!(
        (plain_order - 4.0).abs() < 0.2,
        "uncorrected order ratio {plain_order}"
    );

    let corrected = cone_error(true, 100.0);
    assert!(corrected < plain / 50.0, "corrected {corrected} vs {plain}");
    let corrected_order = corrected / cone_error(true, 200.0);
    assert!(
        (6.0..10.0).contains(&corrected_order),
        "corrected order ratio {corrected_order}"
    );
    // At 1 kHz the corrected integration is within 1e-7 rad of the exact attitude after 10 s.
    let fine = cone_error(true, 1000.0);
    assert!(fine < 1e-7, "1 kHz corrected error {fine}");
}

#[test]
fn static_level_vehicle_stays_level_with_zero_velocity() {
    let start = at_45_deg();
    let mut nav = strapdown(start, true);
    for _ in 0..60_000 {
        let g = nav.gravity();
        assert!(nav.propagate([0.0; 3], [0.0, 0.0, -g], 1e-3).is_applied());
    }
    let s = nav.state();
    assert_eq!(s.velocity_ned, Vector3::zeros());
    assert_eq!(s.attitude, UnitQuaternion::identity());
    assert_eq!((s.lat, s.lon, s.alt), (start.lat, start.lon, start.alt));
}

#[test]
fn static_tilted_vehicle_with_known_biases_has_no_drift() {
    let q = quaternion_from_euler(0.4, -0.25, 2.0);
    let mut state = at_45_deg();
    state.attitude = q;
    let bias = ImuBias {
        gyro_rps: Vector3::new(0.01, -0.02, 0.003),
        accel_mps2: Vector3::new(0.05, 0.02, -0.1),
    };
    let mut nav = Strapdown::new(state, bias, StrapdownConfig::default());
    for _ in 0..60_000 {
        let f = common::specific_force_at_rest(&q, nav.gravity()) + bias.accel_mps2;
        assert!(
            nav.propagate(bias.gyro_rps.into(), f.into(), 1e-3)
                .is_applied()
        );
    }
    let s = nav.state();
    assert!(s.velocity_ned.norm() < 1e-9, "{}", s.velocity_ned);
    assert!(s.attitude.angle_to(&q) < 1e-12);
    assert!((s.alt - 100.0).abs() < 1e-7);
}

#[test]
fn specific_force_is_rotated_with_the_mid_interval_attitude() {
    // Level vehicle yawing at w while accelerating north at a in NED. With mean-over-interval samples and the
    // mid-interval attitude the north velocity is a T sinc(w dt/2) and the east velocity is exactly zero;
    // rotating with the start-of-interval attitude would leave v_E = −a w dt T / 2 = −5e-3 m/s here.
    let (w, a, dt, steps) = (1.0, 1.0, 1e-3, 10_000);
    let mut nav = strapdown(at_45_deg(), true);
    for k in 0..steps {
        let (p0, p1) = (w * k as f64 * dt, w * (k + 1) as f64 * dt);
        let mean_cos = (p1.sin() - p0.sin()) / (w * dt);
        let mean_sin = (p0.cos() - p1.cos()) / (w * dt);
        let g = nav.gravity();
        let f = [a * mean_cos, -a * mean_sin, -g];
        assert!(nav.propagate([0.0, 0.0, w], f, dt).is_applied());
    }
    let half = 0.5 * w * dt;
    let expected_north = a * dt * steps as f64 * half.sin() / half;
    let v = nav.state().velocity_ned;
    assert!(
        (v.x - expected_north).abs() < 1e-9,
        "{} vs {expected_north}",
        v.x
    );
    assert!(v.y.abs() < 1e-9, "east {}", v.y);
    let yaw = euler_from_quaternion(&nav.state().attitude)[2];
    assert!(common::angle_diff(yaw, w * dt * steps as f64).abs() < 1e-9);
}

/// Propagates a level vehicle at constant NED velocity, cancelling gravity exactly each step.
fn coast(velocity: Vector3<f64>, seconds: f64, dt: f64) -> (NominalState, NominalState) {
    let mut start = at_45_deg();
    start.velocity_ned = velocity;
    let mut nav = strapdown(start, true);
    for _ in 0..(seconds / dt).round() as usize {
        let g = nav.gravity();
        assert!(nav.propagate([0.0; 3], [0.0, 0.0, -g], dt).is_applied());
    }
    (start, *nav.state())
}

#[test]
fn constant_north_velocity_advances_latitude_by_v_t_over_meridian_radius() {
    let (v, t) = (10.0, 100.0);
    let (start, end) = coast(Vector3::new(v, 0.0, 0.0), t, 1e-2);
    // Δφ = v t / (R_N + h), with R_N at the middle latitude to second order over the 1 km track.
    let mut dlat = v * t / (meridian_radius(start.lat) + start.alt);
    for _ in 0..3 {
        dlat = v * t / (meridian_radius(start.lat + 0.5 * dlat) + start.alt);
    }
    assert!(
        (end.lat - start.lat - dlat).abs() < 1e-13,
        "{} vs {dlat}",
        end.lat - start.lat
    );
    assert!((end.lon - start.lon).abs() < 1e-15);
    assert!((end.alt - start.alt).abs() < 1e-9);
    assert_eq!(end.velocity_ned, start.velocity_ned);
}

#[test]
fn constant_east_velocity_advances_longitude_and_down_velocity_lowers_height() {
    let (v, t) = (10.0, 100.0);
    let (start, end) = coast(Vector3::new(0.0, v, 0.0), t, 1e-2);
    let dlon = v * t / ((prime_vertical_radius(start.lat) + start.alt) * start.lat.cos());
    assert!((end.lon - start.lon - dlon).abs() < 1e-13);
    assert!((end.lat - start.lat).abs() < 1e-15);

    let (start, end) = coast(Vector3::new(0.0, 0.0, -2.0), 50.0, 1e-2);
    assert!((end.alt - start.alt - 100.0).abs() < 1e-9);
    assert!((end.velocity_ned.z + 2.0).abs() < 1e-12);
}

#[test]
fn constant_acceleration_integrates_velocity_and_position() {
    let (a, dt, steps) = (0.5, 1e-3, 20_000);
    let mut nav = strapdown(at_45_deg(), true);
    let start = *nav.state();
    for _ in 0..steps {
        let g = nav.gravity();
        assert!(nav.propagate([0.0; 3], [a, 0.0, -g], dt).is_applied());
    }
    let t = dt * steps as f64;
    let s = nav.state();
    assert!((s.velocity_ned.x - a * t).abs() < 1e-10);
    let north_m = (s.lat - start.lat) * (meridian_radius(0.5 * (s.lat + start.lat)) + start.alt);
    assert!((north_m - 0.5 * a * t * t).abs() < 1e-6, "{north_m}");
}

#[test]
fn invalid_steps_are_rejected_and_leave_the_state_untouched() {
    let mut nav = strapdown(at_45_deg(), true);
    let before = nav.clone();
    for dt in [0.0, -1e-3, 0.5, f64::NAN, f64::INFINITY] {
        assert_eq!(
            nav.propagate([0.1; 3], [1.0; 3], dt),
            StepOutcome::InvalidDt
        );
    }
    assert_eq!(
        nav.propagate([f64::NAN, 0.0, 0.0], [1.0; 3], 1e-3),
        StepOutcome::NonFiniteInput
    );
    assert_eq!(
        nav.propagate([0.0; 3], [0.0, f64::INFINITY, 0.0], 1e-3),
        StepOutcome::NonFiniteInput
    );
    assert_eq!(nav, before);
}

#[test]
fn longitude_wraps_across_the_antimeridian() {
    let mut start = NominalState::at_rest(0.0, PI - 1e-7, 0.0);
    start.velocity_ned = Vector3::new(0.0, 10.0, 0.0);
    let mut nav = strapdown(start, true);
    for _ in 0..100 {
        let g = nav.gravity();
        let _ = nav.propagate([0.0; 3], [0.0, 0.0, -g], 1e-2);
    }
    let lon = nav.state().lon;
    assert!(lon < 0.0 && lon > -PI, "{lon}");
    assert!((wrap_pi(lon - (PI - 1e-7)) - 10.0 / 6_378_137.0).abs() < 1e-12);
}

proptest! {
    #[test]
    fn euler_round_trip_away_from_gimbal_lock(
        roll in -3.1f64..3.1,
        pitch in -1.5f64..1.5,
        yaw in -3.1f64..3.1,
    ) {
        let q = quaternion_from_euler(roll, pitch, yaw);
        prop_assert!((q.as_ref().norm() - 1.0).abs() < 1e-14);
        let [r, p, y] = euler_from_quaternion(&q);
        prop_assert!(common::angle_diff(r, roll).abs() < 1e-9);
        prop_assert!((p - pitch).abs() < 1e-9);
        prop_assert!(common::angle_diff(y, yaw).abs() < 1e-9);
    }

    #[test]
    fn quaternion_round_trip_through_euler(
        axis in prop::array::uniform3(-1.0f64..1.0),
        angle in 0.0f64..3.1,
    ) {
        let v = Vector3::from(axis);
        prop_assume!(v.norm() > 1e-3);
        let q = rotation_vector_to_quaternion(&(v.normalize() * angle));
        let [r, p, y] = euler_from_quaternion(&q);
        prop_assume!(p.abs() < 1.5);
        prop_assert!(quaternion_from_euler(r, p, y).angle_to(&q) < 1e-9);
    }
}
