//! The navigator end to end on synthetic static data: alignment, propagation, baro and glitches.

mod common;

use common::{Noise, earth_field_ned, specific_force_at_rest};
use ipc_types::{NavMode, NavState, aiding};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rins_navigator::earth::normal_gravity;
use rins_navigator::mechanisation::quaternion_from_euler;
use rins_navigator::{AlignError, NavOutput, Navigator, NavigatorConfig};

const T0_US: u64 = 5_000_000;
const ACCEL_SIGMA: f64 = 0.05;
const GYRO_SIGMA: f64 = 0.001;
const BARO_SIGMA: f64 = 0.3;
const BARO_HEIGHT: f64 = 450.0;

fn config() -> NavigatorConfig {
    NavigatorConfig {
        initial_latitude_deg: 47.0,
        initial_longitude_deg: 8.0,
        initial_altitude_m: 400.0,
        declination_deg: 2.0,
        ..NavigatorConfig::default()
    }
}

/// A static vehicle with biased, noisy sensors: IMU at 1 kHz, magnetometer at 100 Hz, baro at 25 Hz.
struct StaticVehicle {
    attitude: UnitQuaternion<f64>,
    gyro_bias: Vector3<f64>,
    accel_bias: Vector3<f64>,
    gravity: f64,
    field_body: Vector3<f64>,
    noise: Noise,
    with_baro: bool,
}

impl StaticVehicle {
    fn new(seed: u64) -> Self {
        let attitude =
            quaternion_from_euler(3f64.to_radians(), -2f64.to_radians(), 60f64.to_radians());
        Self {
            attitude,
            gyro_bias: Vector3::new(0.004, -0.003, 0.002),
            accel_bias: Vector3::new(0.02, -0.01, 0.03),
            gravity: normal_gravity(47f64.to_radians(), BARO_HEIGHT),
            field_body: attitude.inverse() * earth_field_ned(21.0, 43.0, 2f64.to_radians()),
            noise: Noise::new(seed),
            with_baro: true,
        }
    }

    /// Feeds sample `k` (device time T0 + k ms) and returns the IMU output.
    fn step(&mut self, nav: &mut Navigator, k: u64) -> Option<NavOutput> {
        let t = T0_US + k * 1000;
        if k.is_multiple_of(10) {
            nav.on_mag(t, (self.field_body + self.noise.vector(0.2)).into());
        }
        if self.with_baro && k.is_multiple_of(40) {
            nav.on_baro(t, BARO_HEIGHT + self.noise.scalar(BARO_SIGMA), true);
        }
        let rate = self.gyro_bias + self.noise.vector(GYRO_SIGMA);
        let f = specific_force_at_rest(&self.attitude, self.gravity)
            + self.accel_bias
            + self.noise.vector(ACCEL_SIGMA);
        nav.on_imu(t, rate.into(), f.into())
    }
}

fn attitude_of(out: &NavOutput) -> UnitQuaternion<f64> {
    let [w, x, y, z] = out.quaternion;
    UnitQuaternion::new_normalize(Quaternion::new(w, x, y, z))
}

#[test]
fn aligns_after_one_second_then_navigates_a_static_vehicle_within_predicted_drift() {
    let mut nav = Navigator::new(config()).unwrap();
    let mut vehicle = StaticVehicle::new(11);
    assert_eq!(nav.output().mode, NavMode::Aligning);
    for k in 0..1000 {
        assert_eq!(vehicle.step(&mut nav, k), None, "sample {k}");
    }
    // The sample at T0 + 1 s completes the window and is the reference epoch.
    let first = vehicle.step(&mut nav, 1000).expect("aligned");
    assert_eq!(first.mode, NavMode::Navigating);
    assert_eq!(first.device_time_us, T0_US + 1_000_000);
    assert!(first.aiding_mag);
    assert_eq!(first.velocity_ned, [0.0; 3]);
    assert!((first.lat - 47f64.to_radians()).abs() < 1e-15);
    assert!((first.lon - 8f64.to_radians()).abs() < 1e-15);
    // Altitude from the first baro reading, not the configured 400 m.
    assert!((first.alt - BARO_HEIGHT).abs() < 5.0 * BARO_SIGMA);
    let bias = nav.strapdown().bias().gyro_rps;
    assert!((bias - vehicle.gyro_bias).amax() < 5.0 * GYRO_SIGMA / 1001f64.sqrt());

    let seconds = 10.0;
    let mut last = first;
    for k in 1001..=1000 + (seconds * 1000.0) as u64 {
        last = vehicle.step(&mut nav, k).expect("navigating");
    }
    assert_eq!(
        last.device_time_us,
        T0_US + 1_000_000 + (seconds * 1e6) as u64
    );
    assert!(last.aiding_baro && last.aiding_mag);
    assert_eq!(nav.rejected_imu_samples(), 0);

    // One-sigma horizontal velocity error from the alignment residuals: initial tilt error
    // σ_f/(g√N) and gyro bias error σ_g/√N tilting gravity, plus the velocity random walk.
    let n = 1001f64.sqrt();
    let g = vehicle.gravity;
    let tilt0 = ACCEL_SIGMA / (g * n);
    let bias_err = GYRO_SIGMA / n;
    let v_sigma = g * (tilt0 * seconds + 0.5 * bias_err * seconds * seconds)
        + ACCEL_SIGMA * (1e-3 * seconds).sqrt();
    let v = Vector3::from(last.velocity_ned);
    assert!(
        v.x.abs() < 5.0 * v_sigma && v.y.abs() < 5.0 * v_sigma,
        "{v} vs σ {v_sigma}"
    );
    let attitude_error = attitude_of(&last).angle_to(&vehicle.attitude);
    // Heading dominates: magnetometer noise 0.2 µT over 100 samples on a 21 µT horizontal field.
    assert!(attitude_error < 5.0 * 0.2 / (21.0 * 10.0) + 5.0 * (tilt0 + bias_err * seconds));
    assert!((last.alt - BARO_HEIGHT).abs() < 1.0, "alt {}", last.alt);
    assert!(v.z.abs() < 0.2, "v_D {}", v.z);
}

#[test]
fn motion_during_the_window_restarts_alignment() {
    let mut nav = Navigator::new(config()).unwrap();
    let mut vehicle = StaticVehicle::new(5);
    // First second: a steady 0.5 rad/s turn.
    let g = vehicle.gravity;
    for k in 0..=1000u64 {
        let out = nav.on_imu(T0_US + k * 1000, [0.0, 0.0, 0.5], [0.0, 0.0, -g]);
        assert_eq!(out, None);
    }
    assert!(matches!(
        nav.last_align_error(),
        Some(AlignError::RateTooHigh { .. })
    ));
    assert_eq!(nav.mode(), NavMode::Aligning);
    // Then static: a fresh 1 s window starts at the next sample.
    let mut aligned_at = None;
    for k in 1001..3000u64 {
        if vehicle.step(&mut nav, k).is_some() {
            aligned_at = Some(k);
            break;
        }
    }
    assert_eq!(aligned_at, Some(2001));
    assert_eq!(nav.last_align_error(), None);
}

#[test]
fn device_time_glitches_are_skipped_without_integrating_the_gap() {
    let mut nav = Navigator::new(config()).unwrap();
    let mut vehicle = StaticVehicle::new(9);
    let mut k = 0;
    while vehicle.step(&mut nav, k).is_none() {
        k += 1;
    }
    let before = nav.output();
    // A 5 s jump in device time: not integrated, the epoch moves to it.
    let g = vehicle.gravity;
    let f = specific_force_at_rest(&vehicle.attitude, g) + vehicle.accel_bias;
    let t_jump = T0_US + k * 1000 + 5_000_000;
    let out = nav
        .on_imu(t_jump, [1.0, 1.0, 1.0], f.into())
        .expect("still navigating");
    assert_eq!(nav.rejected_imu_samples(), 1);
    assert_eq!(out.quaternion, before.quaternion);
    assert_eq!(out.device_time_us, t_jump);
    // Time going backwards and a repeated timestamp are skipped the same way.
    let _ = nav.on_imu(t_jump - 1000, vehicle.gyro_bias.into(), f.into());
    let _ = nav.on_imu(t_jump - 1000, vehicle.gyro_bias.into(), f.into());
    assert_eq!(nav.rejected_imu_samples(), 3);
    // Normal samples integrate again.
    let out = nav
        .on_imu(t_jump, vehicle.gyro_bias.into(), f.into())
        .unwrap();
    assert_eq!(nav.rejected_imu_samples(), 3);
    assert_eq!(out.device_time_us, t_jump);
    let out = nav.on_imu(t_jump + 1000, [f64::NAN; 3], f.into()).unwrap();
    assert_eq!(nav.rejected_imu_samples(), 4);
    assert_eq!(out.device_time_us, t_jump);
}

#[test]
fn without_baro_at_alignment_the_first_valid_reading_sets_the_altitude() {
    let mut nav = Navigator::new(config()).unwrap();
    let mut vehicle = StaticVehicle::new(2);
    vehicle.with_baro = false;
    nav.on_baro(T0_US, 999.0, false);
    let mut k = 0;
    let out = loop {
        if let Some(out) = vehicle.step(&mut nav, k) {
            break out;
        }
        k += 1;
    };
    assert_eq!(out.alt, 400.0);
    assert!(!out.aiding_baro);
    let t = T0_US + k * 1000;
    nav.on_baro(t, 455.0, true);
    let out = nav.output();
    assert_eq!(out.alt, 455.0);
    assert!(out.aiding_baro);
    // Invalid readings are ignored and the flag lapses after the aiding timeout (1 s).
    for j in 1..=1500u64 {
        if j.is_multiple_of(40) {
            nav.on_baro(t + j * 1000, 0.0, false);
        }
        let _ = vehicle.step(&mut nav, k + j);
    }
    let out = nav.output();
    assert!(!out.aiding_baro);
    assert!((out.alt - 455.0).abs() < 1.0);
}

#[test]
fn output_fills_the_ipc_payload() {
    let out = NavOutput {
        device_time_us: 7,
        quaternion: [0.5, 0.5, -0.5, 0.5],
        velocity_ned: [1.0, 2.0, 3.0],
        lat: 0.1,
        lon: 0.2,
        alt: 30.0,
        mode: NavMode::Navigating,
        aiding_baro: true,
        aiding_mag: false,
    };
    let mut state = NavState::default();
    out.write_nav_state(&mut state);
    assert_eq!(state.mode, NavMode::Navigating as u8);
    assert_eq!(state.aiding, aiding::BARO);
    assert_eq!(state.quaternion, out.quaternion);
    assert_eq!(state.velocity_ned_mps, out.velocity_ned);
    assert_eq!(
        (state.latitude_rad, state.longitude_rad, state.altitude_m),
        (0.1, 0.2, 30.0)
    );
}

#[test]
fn configuration_parses_partially_and_rejects_unknown_or_out_of_range_fields() {
    let parsed: NavigatorConfig =
        toml::from_str("align_s = 2.0\ninitial_latitude_deg = 47.5\n").unwrap();
    assert_eq!(parsed.align_s, 2.0);
    assert_eq!(parsed.initial_latitude_deg, 47.5);
    assert_eq!(parsed.baro_time_constant_s, 5.0);
    assert!(parsed.validate().is_ok());
    assert!(toml::from_str::<NavigatorConfig>("align_seconds = 2.0\n").is_err());

    type Spoil = fn(&mut NavigatorConfig);
    let cases: [(&str, Spoil); 6] = [
        ("align_s", |c| c.align_s = -1.0),
        ("initial_latitude_deg", |c| c.initial_latitude_deg = 91.0),
        ("initial_longitude_deg", |c| {
            c.initial_longitude_deg = f64::NAN
        }),
        ("baro_time_constant_s", |c| c.baro_time_constant_s = 0.0),
        ("max_dt_s", |c| c.max_dt_s = f64::INFINITY),
        ("align_max_rate_std_rps", |c| {
            c.align_max_rate_std_rps = -0.1
        }),
    ];
    for (field, spoil) in cases {
        let mut c = NavigatorConfig::default();
        spoil(&mut c);
        let error = Navigator::new(c).unwrap_err();
        assert_eq!(error.field, format!("navigator.{field}"));
        assert!(error.to_string().contains(field));
    }
    let c = NavigatorConfig {
        align_s: -1.0,
        ..NavigatorConfig::default()
    };
    assert_eq!(c.validate().unwrap_err().value, "-1");
}
