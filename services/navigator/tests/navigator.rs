//! The navigator end to end on synthetic static data: alignment, propagation, baro and
//! magnetometer aiding, glitches.

mod common;

use common::{Noise, earth_field_ned, specific_force_at_rest};
use ipc_types::{Integrity, NavMode, NavState, aiding, integrity_reason};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rins_earth::normal_gravity;
use rins_navigator::ekf::{AidingCounts, AidingSource};
use rins_navigator::mechanisation::quaternion_from_euler;
use rins_navigator::{AlignError, NavOutput, Navigator, NavigatorConfig};

const T0_US: u64 = 5_000_000;
const ACCEL_SIGMA: f64 = 0.05;
const GYRO_SIGMA: f64 = 0.001;
const BARO_SIGMA: f64 = 0.3;
const BARO_HEIGHT: f64 = 450.0;

fn config() -> NavigatorConfig {
    NavigatorConfig {
        initial_latitude_deg: Some(47.0),
        initial_longitude_deg: Some(8.0),
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
    /// Added to every baro reading, m (a change of weather).
    baro_offset: f64,
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
            baro_offset: 0.0,
        }
    }

    /// Feeds sample `k` (device time T0 + k ms) and returns the IMU output.
    fn step(&mut self, nav: &mut Navigator, k: u64) -> Option<NavOutput> {
        let t = T0_US + k * 1000;
        if k.is_multiple_of(10) {
            let _ = nav.on_mag(t, (self.field_body + self.noise.vector(0.2)).into());
        }
        if self.with_baro && k.is_multiple_of(40) {
            let _ = nav.on_baro(
                t,
                BARO_HEIGHT + self.baro_offset + self.noise.scalar(BARO_SIGMA),
                BARO_SIGMA * BARO_SIGMA,
                true,
            );
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
    assert!(first.aided_by(aiding::MAG));
    assert_eq!(first.velocity_ned, [0.0; 3]);
    assert!((first.lat - 47f64.to_radians()).abs() < 1e-15);
    assert!((first.lon - 8f64.to_radians()).abs() < 1e-15);
    // Altitude from the first baro reading, not the configured 400 m.
    assert!((first.alt - BARO_HEIGHT).abs() < 5.0 * BARO_SIGMA);
    let bias = nav.ekf().unwrap().bias().gyro_rps;
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
    assert!(last.aided_by(aiding::BARO) && last.aided_by(aiding::MAG));
    let baro = last.counts[AidingSource::Baro as usize];
    let mag = last.counts[AidingSource::Mag as usize];
    // Baro at 25 Hz and the magnetometer limited to 10 Hz over 10 s; the gate (5σ) passes all.
    assert_eq!((baro.accepted, baro.rejected), (250, 0));
    assert_eq!((mag.accepted, mag.rejected), (100, 0));
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
    let _ = nav.on_baro(T0_US, 999.0, 1.0, false);
    let mut k = 0;
    let out = loop {
        if let Some(out) = vehicle.step(&mut nav, k) {
            break out;
        }
        k += 1;
    };
    assert_eq!(out.alt, 400.0);
    assert!(!out.aided_by(aiding::BARO));
    let t = T0_US + k * 1000;
    let _ = nav.on_baro(t, 455.0, 1.0, true);
    let out = nav.output();
    assert_eq!(out.alt, 455.0);
    // The first reading sets the altitude; the following ones are updates.
    let _ = nav.on_baro(t, 455.0, 1.0, true);
    assert!(nav.output().aided_by(aiding::BARO));
    // Invalid readings are ignored and the flag lapses after the aiding timeout (1 s).
    for j in 1..=1500u64 {
        if j.is_multiple_of(40) {
            let _ = nav.on_baro(t + j * 1000, 0.0, 1.0, false);
        }
        let _ = vehicle.step(&mut nav, k + j);
    }
    let out = nav.output();
    assert!(!out.aided_by(aiding::BARO));
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
        aiding: aiding::BARO | aiding::ZUPT,
        covariance_diag: std::array::from_fn(|k| k as f64),
        counts: [
            AidingCounts {
                accepted: 5,
                rejected: 1,
            },
            AidingCounts::default(),
            AidingCounts {
                accepted: u64::MAX,
                rejected: 0,
            },
            AidingCounts::default(),
            AidingCounts::default(),
            AidingCounts::default(),
            // Airspeed, the last source, carried like the others.
            AidingCounts {
                accepted: 9,
                rejected: u64::from(u32::MAX) + 1,
            },
        ],
        gyro_bias_rps: [1e-3, -2e-3, 3e-3],
        accel_bias_mps2: [0.1, 0.2, -0.3],
        integrity: Integrity::Degraded,
        integrity_reasons: integrity_reason::MAG_INCONSISTENT | integrity_reason::RECOVERING,
        resets: [0, 2, 0, 0, 0, 0, 0],
    };
    let mut state = NavState::default();
    out.write_nav_state(&mut state);
    assert_eq!(state.integrity, Integrity::Degraded as u8);
    assert_eq!(
        state.integrity_reasons,
        integrity_reason::MAG_INCONSISTENT | integrity_reason::RECOVERING
    );
    assert_eq!(state.gyro_bias_rps, [1e-3, -2e-3, 3e-3]);
    assert_eq!(state.accel_bias_mps2, [0.1, 0.2, -0.3]);
    assert_eq!(state.mode, NavMode::Navigating as u8);
    assert_eq!(state.aiding, aiding::BARO | aiding::ZUPT);
    assert_eq!(state.covariance_diag, out.covariance_diag);
    // Counts saturate rather than wrap.
    assert_eq!(state.aiding_accepted, [5, 0, u32::MAX, 0, 0, 0, 9]);
    assert_eq!(state.aiding_rejected, [1, 0, 0, 0, 0, 0, u32::MAX]);
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
        toml::from_str("align_s = 2.0\ninitial_latitude_deg = 47.5\ninitial_longitude_deg = 8.5\n")
            .unwrap();
    assert_eq!(parsed.align_s, 2.0);
    assert_eq!(parsed.initial_latitude_deg, Some(47.5));
    assert!(parsed.baro.enabled && parsed.mag.enabled);
    assert!(parsed.validate().is_ok());
    assert!(toml::from_str::<NavigatorConfig>("align_seconds = 2.0\n").is_err());

    type Spoil = fn(&mut NavigatorConfig);
    let cases: [(&str, Spoil); 14] = [
        ("align_s", |c| c.align_s = -1.0),
        ("gyro_lag_s", |c| c.gyro_lag_s = 0.2),
        ("gyro_lag_s", |c| c.gyro_lag_s = -0.001),
        ("initial_latitude_deg", |c| {
            (c.initial_latitude_deg, c.initial_longitude_deg) = (Some(91.0), Some(0.0))
        }),
        ("initial_longitude_deg", |c| {
            (c.initial_latitude_deg, c.initial_longitude_deg) = (Some(0.0), Some(f64::NAN))
        }),
        // One of the pair alone is refused, naming it.
        ("initial_latitude_deg", |c| {
            c.initial_latitude_deg = Some(47.0)
        }),
        ("initial_longitude_deg", |c| {
            c.initial_longitude_deg = Some(8.0)
        }),
        ("baro.sigma_floor_m", |c| c.baro.sigma_floor_m = 0.0),
        ("max_dt_s", |c| c.max_dt_s = f64::INFINITY),
        ("align_max_rate_std_rps", |c| {
            c.align_max_rate_std_rps = -0.1
        }),
        ("mag.inflation", |c| c.mag.inflation = 0.5),
        ("airspeed.sigma_mps", |c| c.airspeed.sigma_mps = -1.0),
        ("airspeed.offset_pa", |c| c.airspeed.offset_pa = f64::NAN),
        ("mag_calibration", |c| {
            c.mag_calibration.hard_iron_ut[1] = f64::NAN
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

/// Heading error of the output against the vehicle, rad.
fn heading_error(out: &NavOutput, truth: &UnitQuaternion<f64>) -> f64 {
    let yaw = |q: &UnitQuaternion<f64>| q.euler_angles().2;
    rins_navigator::attitude::wrap_pi(yaw(&attitude_of(out)) - yaw(truth))
}

/// After alignment the magnetometer reads a field turned 5° about the vertical, either with the
/// reference magnitude (undetectable: the heading must follow it) or also 40 % stronger (a
/// disturbance: the adaptive σ grows tenfold times the ratio and the heading must hold).
fn heading_after_turned_field(stronger: f64) -> f64 {
    let mut nav = Navigator::new(config()).unwrap();
    let mut vehicle = StaticVehicle::new(5);
    let mut k = 0;
    while vehicle.step(&mut nav, k).is_none() {
        k += 1;
    }
    let turn = UnitQuaternion::from_euler_angles(0.0, 0.0, 5f64.to_radians());
    let field_ned = earth_field_ned(21.0, 43.0, 2f64.to_radians());
    vehicle.field_body = vehicle.attitude.inverse() * (turn * field_ned) * stronger;
    let mut out = nav.output();
    for j in 1..=20_000 {
        out = vehicle.step(&mut nav, k + j).unwrap();
    }
    heading_error(&out, &vehicle.attitude)
}

/// Where a scalar Kalman filter with prior σ₀ (the configured initial heading σ) ends after `n`
/// updates of σ `sigma_deg` all measuring `step_deg`: `step · n P₀ / (R + n P₀)`.
fn scalar_filter_end(step_deg: f64, sigma_deg: f64, n: f64) -> f64 {
    let p0 = NavigatorConfig::default()
        .ekf
        .initial_heading_sigma
        .to_degrees()
        .powi(2);
    step_deg * n * p0 / (sigma_deg * sigma_deg + n * p0)
}

#[test]
fn magnetometer_updates_follow_an_undisturbed_field_and_hold_against_a_disturbed_one() {
    // 200 updates (10 Hz for 20 s). The field is turned east, so the vehicle appears turned west.
    // Undisturbed: σ = 2°, each innovation inside the 5σ gate; the estimate ends on the field's
    // heading, −5°. Tolerance: the gyro noise and bias-error drift over 20 s and 2°/√200 of
    // measurement noise, about 0.3°.
    let followed = heading_after_turned_field(1.0).to_degrees();
    let expected = scalar_filter_end(-5.0, 2.0, 200.0);
    assert!(
        (followed - expected).abs() < 0.3,
        "{followed} vs {expected}"
    );
    // Disturbed: |m| 40 % above the reference, ratio 0.4 · 47.85 µT / 5 µT = 3.83, so
    // σ = 2° · 10 · 3.83 = 76.6°: the estimate moves only part of the way.
    let held = heading_after_turned_field(1.4).to_degrees();
    let sigma = 2.0 * 10.0 * 0.4 * 21f64.hypot(43.0) / 5.0;
    let expected_held = scalar_filter_end(-5.0, sigma, 200.0);
    assert!(
        (held - expected_held).abs() < 0.3,
        "{held} vs {expected_held}"
    );
    assert!(held > followed + 0.8, "{held} vs {followed}");
}

#[test]
fn a_baro_outage_is_flagged_and_the_returning_baro_re_sets_the_altitude() {
    let mut nav = Navigator::new(config()).unwrap();
    let mut vehicle = StaticVehicle::new(9);
    let mut k = 0;
    while vehicle.step(&mut nav, k).is_none() {
        k += 1;
    }
    let mut run = |vehicle: &mut StaticVehicle, nav: &mut Navigator, samples: u64| {
        for _ in 0..samples {
            k += 1;
            let _ = vehicle.step(nav, k);
        }
        nav.output()
    };
    let out = run(&mut vehicle, &mut nav, 2000);
    assert!(out.aided_by(aiding::BARO) && !out.aided_by(aiding::BARO_STALE));
    // 5 s without a reading: stale after the 1 s aiding timeout, no longer counted as aiding.
    vehicle.with_baro = false;
    let out = run(&mut vehicle, &mut nav, 5000);
    assert!(out.aided_by(aiding::BARO_STALE) && !out.aided_by(aiding::BARO));
    let before = out.counts[AidingSource::Baro as usize];
    // The baro returns 30 m higher: sixty times the 0.5 m σ floor, far outside the 5σ gate. The
    // first reading re-sets the altitude; the next ones are ordinary updates and all pass.
    vehicle.with_baro = true;
    vehicle.baro_offset = 30.0;
    let out = run(&mut vehicle, &mut nav, 2000);
    assert!(out.aided_by(aiding::BARO) && !out.aided_by(aiding::BARO_STALE));
    assert!(
        (out.alt - (BARO_HEIGHT + 30.0)).abs() < 5.0 * BARO_SIGMA,
        "alt {}",
        out.alt
    );
    let after = out.counts[AidingSource::Baro as usize];
    assert_eq!(after.rejected, before.rejected);
    // 2 s at 25 Hz: 50 readings, the first re-sets, 49 updates.
    assert_eq!(after.accepted - before.accepted, 49);
}
