//! Static alignment against known attitudes, biases and noise levels.

mod common;

use std::f64::consts::PI;

use common::{Noise, angle_diff, earth_field_ned, specific_force_at_rest};
use nalgebra::{UnitQuaternion, Vector3};
use rins_navigator::alignment::{AlignConfig, AlignError, StaticAligner};
use rins_navigator::mechanisation::quaternion_from_euler;

const G: f64 = 9.806;
const IMU_HZ: u64 = 1000;
const MAG_HZ: u64 = 100;
const ACCEL_SIGMA: f64 = 0.05;
const GYRO_SIGMA: f64 = 0.005;
const MAG_SIGMA: f64 = 0.3;
const FIELD_HORIZONTAL: f64 = 20.0;
const FIELD_DOWN: f64 = 45.0;

fn config() -> AlignConfig {
    AlignConfig {
        gravity_mps2: G,
        ..AlignConfig::default()
    }
}

/// A 1 s window (1001 IMU samples, 100 mag samples) of a static vehicle.
struct Scene {
    attitude: UnitQuaternion<f64>,
    gyro_bias: Vector3<f64>,
    declination: f64,
    with_mag: bool,
}

impl Scene {
    fn fill(&self, aligner: &mut StaticAligner, noise: &mut Noise) {
        let f_true = specific_force_at_rest(&self.attitude, G);
        let field_ned = earth_field_ned(FIELD_HORIZONTAL, FIELD_DOWN, self.declination);
        let field_body = self.attitude.inverse() * field_ned;
        for k in 0..=IMU_HZ {
            let t = k * 1_000_000 / IMU_HZ;
            let rate = self.gyro_bias + noise.vector(GYRO_SIGMA);
            let f = f_true + noise.vector(ACCEL_SIGMA);
            assert!(aligner.push_imu(t, rate.into(), f.into()));
            if self.with_mag && k.is_multiple_of(IMU_HZ / MAG_HZ) && k < IMU_HZ {
                assert!(aligner.push_mag(t, (field_body + noise.vector(MAG_SIGMA)).into()));
            }
        }
    }
}

#[test]
fn without_the_window_bias_the_attitude_is_the_same_and_the_bias_zero() {
    let scene = Scene {
        attitude: quaternion_from_euler(0.05, -0.1, 1.0),
        gyro_bias: Vector3::new(0.01, -0.02, 0.005),
        declination: 0.0,
        with_mag: true,
    };
    let mut with = StaticAligner::new(config());
    let mut without = StaticAligner::new(AlignConfig {
        gyro_bias_from_window: false,
        ..config()
    });
    scene.fill(&mut with, &mut Noise::new(7));
    scene.fill(&mut without, &mut Noise::new(7));
    let (a, b) = (
        with.finish(0.0).expect("aligns"),
        without.finish(0.0).expect("aligns"),
    );
    assert_eq!(b.gyro_bias_rps, Vector3::zeros());
    assert!(a.gyro_bias_rps.norm() > 0.02);
    assert_eq!(a.attitude, b.attitude);
}

#[test]
fn recovers_roll_pitch_heading_and_gyro_bias_within_noise_bounds() {
    let (roll, pitch, yaw) = (5f64.to_radians(), -8f64.to_radians(), 130f64.to_radians());
    let declination = 10f64.to_radians();
    let scene = Scene {
        attitude: quaternion_from_euler(roll, pitch, yaw),
        gyro_bias: Vector3::new(0.01, -0.02, 0.005),
        declination,
        with_mag: true,
    };
    let n = (IMU_HZ + 1) as f64;
    let m = MAG_HZ as f64;
    // One-sigma errors from white noise averaged over the window.
    let tilt_sigma = ACCEL_SIGMA / (G * pitch.cos() * n.sqrt());
    let heading_sigma = ((MAG_SIGMA / (FIELD_HORIZONTAL * m.sqrt())).powi(2)
        + (FIELD_DOWN / FIELD_HORIZONTAL * tilt_sigma).powi(2))
    .sqrt();
    let bias_sigma = GYRO_SIGMA / n.sqrt();

    let mut roll_sq = 0.0;
    let trials = 64;
    for seed in 0..trials {
        let mut aligner = StaticAligner::new(config());
        scene.fill(&mut aligner, &mut Noise::new(seed));
        assert!(aligner.is_complete());
        let a = aligner.finish(declination).expect("static window aligns");
        assert!(a.heading_aided);
        assert_eq!((a.imu_samples, a.mag_samples), (1001, 100));
        assert!(
            angle_diff(a.roll, roll).abs() < 5.0 * tilt_sigma,
            "roll {}",
            a.roll
        );
        assert!(
            (a.pitch - pitch).abs() < 5.0 * tilt_sigma,
            "pitch {}",
            a.pitch
        );
        assert!(
            angle_diff(a.yaw, yaw).abs() < 5.0 * heading_sigma,
            "yaw {}",
            a.yaw
        );
        assert!((a.gyro_bias_rps - scene.gyro_bias).amax() < 5.0 * bias_sigma);
        assert!(a.attitude.angle_to(&scene.attitude) < 5.0 * heading_sigma);
        roll_sq += angle_diff(a.roll, roll).powi(2);
    }
    // The spread over trials is the predicted one (64 trials: ±9 % one-sigma on the RMS).
    let roll_rms = (roll_sq / trials as f64).sqrt();
    assert!(
        (0.6..1.4).contains(&(roll_rms / tilt_sigma)),
        "roll RMS {roll_rms} vs predicted {tilt_sigma}"
    );
}

#[test]
fn heading_is_exact_without_noise_in_every_quadrant_and_attitude() {
    for &(roll, pitch) in &[(0.0, 0.0), (0.5, -0.4), (-1.0, 1.2), (2.5, 0.3)] {
        for yaw_deg in [-170.0, -90.0, -30.0, 0.0, 45.0, 90.0, 179.0] {
            let yaw = f64::to_radians(yaw_deg);
            let declination = -0.2;
            let q = quaternion_from_euler(roll, pitch, yaw);
            let mut aligner = StaticAligner::new(config());
            let field = q.inverse() * earth_field_ned(FIELD_HORIZONTAL, FIELD_DOWN, declination);
            let f = specific_force_at_rest(&q, G);
            aligner.push_mag(0, field.into());
            for t in [0, 500_000, 1_000_000] {
                aligner.push_imu(t, [0.0; 3], f.into());
            }
            let a = aligner.finish(declination).unwrap();
            assert!(angle_diff(a.roll, roll).abs() < 1e-12);
            assert!((a.pitch - pitch).abs() < 1e-12);
            assert!(
                angle_diff(a.yaw, yaw).abs() < 1e-12,
                "{roll} {pitch} {yaw}: {}",
                a.yaw
            );
            assert!(a.yaw > -PI && a.yaw <= PI);
        }
    }
}

#[test]
fn without_magnetometer_heading_is_zero_and_flagged_unaided() {
    let scene = Scene {
        attitude: quaternion_from_euler(0.1, 0.2, 2.0),
        gyro_bias: Vector3::zeros(),
        declination: 0.0,
        with_mag: false,
    };
    let mut aligner = StaticAligner::new(config());
    scene.fill(&mut aligner, &mut Noise::new(7));
    let a = aligner.finish(0.3).unwrap();
    assert!(!a.heading_aided);
    assert_eq!(a.yaw, 0.0);
    assert_eq!(a.mean_field_ut, None);
    assert!((a.roll - 0.1).abs() < 1e-3 && (a.pitch - 0.2).abs() < 1e-3);
}

#[test]
fn incomplete_window_is_reported() {
    let mut aligner = StaticAligner::new(config());
    aligner.push_imu(0, [0.0; 3], [0.0, 0.0, -G]);
    aligner.push_imu(999_000, [0.0; 3], [0.0, 0.0, -G]);
    assert!(!aligner.is_complete());
    match aligner.finish(0.0) {
        Err(AlignError::Incomplete { samples: 2, .. }) => {}
        other => panic!("{other:?}"),
    }
}

/// Feeds 1 s at 1 kHz of `sample(t)` = (rate, specific force) and returns the verdict.
fn window(sample: impl Fn(f64) -> (Vector3<f64>, Vector3<f64>)) -> Result<(), AlignError> {
    let mut aligner = StaticAligner::new(config());
    let mut noise = Noise::new(3);
    for k in 0..=1000u64 {
        let (rate, f) = sample(k as f64 * 1e-3);
        aligner.push_imu(
            k * 1000,
            (rate + noise.vector(GYRO_SIGMA)).into(),
            (f + noise.vector(ACCEL_SIGMA)).into(),
        );
    }
    aligner.finish(0.0).map(|_| ())
}

#[test]
fn moving_windows_are_rejected() {
    let level = Vector3::new(0.0, 0.0, -G);
    assert_eq!(window(|_| (Vector3::zeros(), level)), Ok(()));

    // A steady turn: its mean rate is far above any plausible gyro bias.
    assert!(matches!(
        window(|_| (Vector3::new(0.0, 0.0, 0.3), level)),
        Err(AlignError::RateTooHigh { .. })
    ));
    // Rocking at 2 Hz: small mean rate, large spread.
    assert!(matches!(
        window(|t| (Vector3::new(0.3 * (4.0 * PI * t).sin(), 0.0, 0.0), level)),
        Err(AlignError::RateUnsteady { .. })
    ));
    // Vibration/handling along x at 5 Hz, 1 m/s².
    assert!(matches!(
        window(|t| (
            Vector3::zeros(),
            level + Vector3::new((10.0 * PI * t).sin(), 0.0, 0.0)
        )),
        Err(AlignError::SpecificForceUnsteady { .. })
    ));
    // A steady vertical acceleration (a lift): |f̄| departs from g.
    assert!(matches!(
        window(|_| (Vector3::zeros(), level * 1.05)),
        Err(AlignError::SpecificForceMagnitude { .. })
    ));
}

#[test]
fn time_going_backwards_restarts_the_window() {
    let mut aligner = StaticAligner::new(config());
    let f = [0.0, 0.0, -G];
    aligner.push_imu(5_000_000, [0.0; 3], f);
    aligner.push_imu(5_900_000, [0.0; 3], f);
    aligner.push_imu(100, [0.0; 3], f);
    assert_eq!(aligner.elapsed_s(), 0.0);
    aligner.push_imu(1_000_100, [0.0; 3], f);
    assert!(aligner.is_complete());
    assert_eq!(aligner.finish(0.0).unwrap().imu_samples, 2);
}

#[test]
fn non_finite_samples_are_ignored() {
    let mut aligner = StaticAligner::new(config());
    assert!(!aligner.push_imu(0, [f64::NAN, 0.0, 0.0], [0.0, 0.0, -G]));
    assert!(!aligner.push_mag(0, [f64::INFINITY, 0.0, 0.0]));
    assert_eq!(aligner.elapsed_s(), 0.0);
}
