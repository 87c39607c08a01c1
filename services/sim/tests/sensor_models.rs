//! Sensor models driven directly: ADC saturation, quantisation, barometer and magnetometer.

mod common;

use nalgebra::{UnitQuaternion, Vector3};
use proptest::prelude::*;
use rins_earth::STANDARD_GRAVITY;
use rins_protocol::{BaroFrame, FrameType, ImuFrame, MagFrame, Payload};
use rins_sim::sensor_model::baro::{isa_altitude_m, isa_pressure_pa};
use rins_sim::sensor_model::{Environment, SensorModel};
use rins_sim::{Scenario, SensorModelConfig, SimConfig, Simulator, TickOutput, TruthState};
use rins_test_support::pyramid::optimal_pyramid_axes;

fn truth(rate: Vector3<f64>, force: Vector3<f64>) -> TruthState {
    TruthState {
        time_s: 0.0,
        attitude: UnitQuaternion::identity(),
        euler_rad: [0.0; 3],
        angular_rate_b: rate,
        specific_force_b: force,
        velocity_n: Vector3::zeros(),
        acceleration_n: Vector3::zeros(),
        latitude_rad: 0.0,
        longitude_rad: 0.0,
        altitude_m: 0.0,
        foot_load: 0.0,
        stance: false,
        rotor: Default::default(),
    }
}

fn model(config: &SensorModelConfig, axes: &[[f64; 3]]) -> SensorModel {
    SensorModel::new(
        config,
        &SimConfig::default().environment(),
        axes,
        axes,
        1000.0,
        11,
    )
    .unwrap()
}

const SATURATION: u16 = ipc_types::status::SATURATION as u16;

#[test]
fn large_rate_saturates_and_clamps_with_status_bit() {
    let axes = optimal_pyramid_axes();
    let mut m = model(&SensorModelConfig::default(), &axes);
    let mut frame = ImuFrame::default();
    let lsb = SensorModelConfig::default().gyro_lsb_rps();

    // 20 rad/s about x: projections ±20·cos(35.26°)·cos(45°) ≈ ±11.5 rad/s, beyond ±5.24 rad/s full scale.
    let rate = Vector3::new(20.0, 0.0, 0.0);
    m.imu(
        &truth(rate, Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)),
        &mut frame,
    );
    assert_eq!(frame.status & SATURATION, SATURATION);
    for (i, axis) in axes.iter().enumerate() {
        let expected = if axis[0] > 0.0 { 2047 } else { -2048 };
        assert_eq!(frame.gyro_counts[i], expected, "gyro {i}");
    }
    // Accelerometers are unaffected and stay well inside their range.
    assert!(frame.accel_counts[..4].iter().all(|c| c.abs() < 2000));

    // 1 rad/s is inside the range: no status bit, counts ≈ projection/lsb.
    let rate = Vector3::new(1.0, 0.0, 0.0);
    m.imu(
        &truth(rate, Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)),
        &mut frame,
    );
    assert_eq!(frame.status & SATURATION, 0);
    for (i, axis) in axes.iter().enumerate() {
        let ideal = axis[0] / lsb;
        assert!(
            (f64::from(frame.gyro_counts[i]) - ideal).abs() < 20.0,
            "gyro {i}"
        );
    }

    // 10 g along z saturates the accelerometers (full scale 8 g).
    m.imu(
        &truth(
            Vector3::zeros(),
            Vector3::new(0.0, 0.0, -10.0 * STANDARD_GRAVITY / 0.57),
        ),
        &mut frame,
    );
    assert_eq!(frame.status & SATURATION, SATURATION);
    assert!(frame.accel_counts[..4].iter().all(|&c| c == -2048));
}

#[test]
fn frame_layout_reports_channel_counts_and_clears_unused_slots() {
    let axes: Vec<[f64; 3]> = (0..6).map(|i| [1.0, f64::from(i) * 0.1, 0.2]).collect();
    let config = SensorModelConfig {
        temperature_sensors: 2,
        ..SensorModelConfig::default()
    };
    let mut m = model(&config, &axes);
    let mut frame = ImuFrame {
        gyro_counts: [99; 16],
        accel_counts: [99; 16],
        temperature_centi_c: [99; 4],
        ..ImuFrame::default()
    };
    m.imu(
        &truth(Vector3::zeros(), Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)),
        &mut frame,
    );
    assert_eq!(
        (frame.n_gyro, frame.n_accel, frame.n_temperature),
        (6, 6, 2)
    );
    assert_eq!(frame.valid_mask, 0x003F_003F);
    assert!(frame.gyro_counts[6..].iter().all(|&c| c == 0));
    assert!(frame.accel_counts[6..].iter().all(|&c| c == 0));
    assert_eq!(&frame.temperature_centi_c[2..], &[0, 0]);
    assert!(
        frame.temperature_centi_c[..2]
            .iter()
            .all(|&c| (2300..2700).contains(&c))
    );
}

proptest! {
    /// With every error switched off the counts are exactly round(h·ω / lsb), clipped to 12 bits,
    /// and the status bit is set exactly when some channel clips.
    #[test]
    fn noiseless_counts_are_rounded_projections(
        wx in -8.0f64..8.0, wy in -8.0f64..8.0, wz in -8.0f64..8.0,
    ) {
        let axes = optimal_pyramid_axes();
        let config = common::noiseless_sensors();
        let lsb = config.gyro_lsb_rps();
        let mut m = model(&config, &axes);
        let mut frame = ImuFrame::default();
        let w = Vector3::new(wx, wy, wz);
        m.imu(&truth(w, Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)), &mut frame);
        let mut any_clipped = false;
        for (i, axis) in axes.iter().enumerate() {
            let raw = (Vector3::from(*axis).normalize().dot(&w) / lsb).round();
            any_clipped |= !(-2048.0..=2047.0).contains(&raw);
            let expected = raw.clamp(-2048.0, 2047.0);
            // Rounding ties may fall either way after the axis normalisation: allow one count only
            // when the raw value is within 1e-9 of a half-count.
            prop_assert!((f64::from(frame.gyro_counts[i]) - expected).abs() <= 1.0);
            if ((Vector3::from(*axis).normalize().dot(&w) / lsb).fract().abs() - 0.5).abs() > 1e-9 {
                prop_assert_eq!(f64::from(frame.gyro_counts[i]), expected);
            }
        }
        prop_assert_eq!(frame.status & SATURATION != 0, any_clipped);
    }
}

/// ISA pressure against the closed form with the textbook exponent 5.25588 and against tabulated
/// standard-atmosphere values; the mean of n samples lies within 5σ/√n of it (σ = 2 Pa).
#[test]
fn baro_pressure_follows_isa() {
    // U.S. Standard Atmosphere 1976 tables.
    for (h, table_pa) in [
        (0.0, 101_325.0),
        (1000.0, 89_874.6),
        (2000.0, 79_495.2),
        (5000.0, 54_019.9),
    ] {
        let closed = 101_325.0 * (1.0 - 0.0065 * h / 288.15_f64).powf(5.25588);
        assert!(
            (isa_pressure_pa(h, 101_325.0) - closed).abs() < 0.05,
            "h={h}"
        );
        assert!(
            (isa_pressure_pa(h, 101_325.0) - table_pa).abs() < 0.1,
            "h={h}"
        );
        assert!((isa_altitude_m(isa_pressure_pa(h, 101_325.0), 101_325.0) - h).abs() < 1e-6);
    }
    let config = SensorModelConfig::default();
    let env = Environment {
        qnh_pa: 100_800.0,
        ..SimConfig::default().environment()
    };
    let axes = optimal_pyramid_axes();
    let mut m = SensorModel::new(&config, &env, &axes, &axes, 1000.0, 5).unwrap();
    let n = 2000;
    for h in [0.0, 488.0, 1500.0, 4000.0] {
        let mut frame = BaroFrame::default();
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            m.baro(h, &mut frame);
            let p = f64::from(frame.pressure_pa);
            sum += p;
            sum2 += p * p;
        }
        let mean = sum / f64::from(n);
        let std = (sum2 / f64::from(n) - mean * mean).sqrt();
        let closed = 100_800.0 * (1.0 - 0.0065 * h / 288.15_f64).powf(5.25588);
        // f32 storage adds at most 0.004 Pa of rounding at 1e5 Pa.
        let tol = 5.0 * config.baro_noise_pa / f64::from(n).sqrt() + 0.05;
        assert!((mean - closed).abs() < tol, "h={h}: {mean} vs {closed}");
        assert!((std / config.baro_noise_pa - 1.0).abs() < 5.0 / (2.0 * f64::from(n)).sqrt());
        let expected_centi = ((15.0 - 0.0065 * h) * 100.0).round() as i16;
        assert!(
            (frame.temperature_centi_c - expected_centi).abs() <= 1,
            "h={h}"
        );
    }
}

fn mean_mag(heading_deg: f64, declination_deg: f64) -> Vector3<f64> {
    let mut config = common::config(Scenario::Static);
    config.initial_heading_deg = heading_deg;
    config.earth_field.declination_deg = declination_deg;
    let axes = optimal_pyramid_axes();
    let mut sim = Simulator::new(&config, &axes, &axes, 9).unwrap();
    let mut out = TickOutput::default();
    let mut sum = Vector3::zeros();
    let mut count = 0.0;
    for _ in 0..10_000 {
        sim.step(&mut out);
        if let Some(frame) = out.frame(FrameType::Mag) {
            let Payload::Mag(mag) = frame.payload else {
                panic!("not a mag frame")
            };
            sum += Vector3::from(mag.field_nt.map(f64::from));
            count += 1.0;
        }
    }
    assert_eq!(count, 1000.0, "100 Hz over 10 s");
    sum / count
}

/// Level, north: body = NED, so the reading is [B cos I, 0, B sin I] (B = 50 µT, I = 60°).
/// Heading 90° puts north on the body's −y axis. With heading equal to the declination the field is
/// again in the body x–z plane. Tolerance: 5σ/√1000 of 100 nT noise, plus half a count of rounding.
#[test]
fn mag_reads_earth_field_rotated_into_body() {
    let (b, dip) = (50_000.0, 60f64.to_radians());
    let tol = 5.0 * 100.0 / 1000f64.sqrt() + 0.5;
    let north = mean_mag(0.0, 0.0);
    let expected = Vector3::new(b * dip.cos(), 0.0, b * dip.sin());
    assert!((north - expected).amax() < tol, "{north} vs {expected}");

    let east = mean_mag(90.0, 0.0);
    let expected = Vector3::new(0.0, -b * dip.cos(), b * dip.sin());
    assert!((east - expected).amax() < tol, "{east} vs {expected}");

    let along_declination = mean_mag(10.0, 10.0);
    let expected = Vector3::new(b * dip.cos(), 0.0, b * dip.sin());
    assert!(
        (along_declination - expected).amax() < tol,
        "{along_declination} vs {expected}"
    );
}

#[test]
fn mag_applies_soft_and_hard_iron() {
    let config = SensorModelConfig {
        mag_noise_ut: 0.0,
        mag_hard_iron_ut: [1.0, -2.0, 3.0],
        mag_soft_iron: [[1.1, 0.0, 0.0], [0.0, 0.9, 0.0], [0.05, 0.0, 1.0]],
        ..SensorModelConfig::default()
    };
    let axes = optimal_pyramid_axes();
    let mut m = model(&config, &axes);
    let mut frame = MagFrame::default();
    m.mag(&UnitQuaternion::identity(), &mut frame);
    let (bx, bz) = (25_000.0, 50_000.0 * 60f64.to_radians().sin());
    let expected =
        [1.1 * bx + 1000.0, -2000.0, 0.05 * bx + bz + 3000.0].map(|v: f64| v.round() as i32);
    assert_eq!(frame.field_nt, expected);
}
