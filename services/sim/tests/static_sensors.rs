//! Static scenario: averaged inertial readings against the model's closed form.
#![allow(clippy::needless_range_loop)] // channel index addresses several parallel arrays

mod common;

use nalgebra::Vector3;
use rins_earth::STANDARD_GRAVITY;
use rins_protocol::Payload;
use rins_sim::{InertialSensor, Scenario, SimConfig, Simulator, TickOutput};
use rins_test_support::pyramid::{block_pyramid_axes, optimal_pyramid_axes};

const SECONDS: usize = 10;

struct Averages {
    gyro: Vec<f64>,
    accel: Vec<f64>,
    temperatures_c: Vec<f64>,
}

fn run(sim: &mut Simulator, steps: usize) -> Averages {
    let mut out = TickOutput::default();
    let (mut gyro, mut accel, mut temps) = (vec![0.0; 4], vec![0.0; 4], vec![0.0; 4]);
    for _ in 0..steps {
        sim.step(&mut out);
        let Payload::Imu(imu) = out.imu.payload else {
            panic!("not an IMU frame")
        };
        assert_eq!(imu.status, 0);
        assert_eq!(imu.valid_mask, 0x000F_000F);
        for i in 0..4 {
            gyro[i] += f64::from(imu.gyro_counts[i]);
            accel[i] += f64::from(imu.accel_counts[i]);
            temps[i] += f64::from(imu.temperature_centi_c[i]) / 100.0;
        }
    }
    let n = steps as f64;
    Averages {
        gyro: gyro.iter().map(|s| s / n).collect(),
        accel: accel.iter().map(|s| s / n).collect(),
        temperatures_c: temps.iter().map(|s| s / n).collect(),
    }
}

/// Per-sample noise of a channel after the ADC: white σ = density·√rate plus uniform quantisation
/// lsb²/12 (the white noise exceeds one lsb, so the rounding error is uncorrelated with the signal).
fn sample_sigma(density_si: f64, rate_hz: f64, lsb: f64) -> f64 {
    ((density_si * rate_hz.sqrt()).powi(2) + lsb * lsb / 12.0).sqrt()
}

#[test]
fn averaged_counts_match_projection_plus_true_errors_within_noise_bounds() {
    let config = common::config(Scenario::Static);
    let axes = optimal_pyramid_axes();
    let mut sim = Simulator::new(&config, &axes, &axes, 7).unwrap();
    let n = SECONDS * 1000;
    let avg = run(&mut sim, n);
    let t_end = sim.time_s();
    let s = &config.sensors;
    let g_lsb = config.gyro_lsb_rps();
    let a_lsb = config.accel_lsb_mps2();
    // 5σ of the mean; the Gauss–Markov and temperature terms move by < 1e-5 of that over 10 s.
    let gyro_tol = 5.0 * sample_sigma(s.gyro_noise_density_dps_rthz.to_radians(), 1000.0, g_lsb)
        / (n as f64).sqrt();
    let accel_tol =
        5.0 * sample_sigma(
            s.accel_noise_density_ug_rthz * 1e-6 * STANDARD_GRAVITY,
            1000.0,
            a_lsb,
        ) / (n as f64).sqrt();
    let f_b = Vector3::new(0.0, 0.0, -STANDARD_GRAVITY);

    let mut sum_abs_gyro_bias = 0.0;
    for i in 0..4 {
        let bias = sim
            .sensors()
            .channel_bias(InertialSensor::Gyro, i, t_end)
            .unwrap();
        let measured = avg.gyro[i] * g_lsb;
        assert!(
            (measured - bias).abs() < gyro_tol,
            "gyro {i}: mean {measured:e} rad/s vs bias {bias:e} (tol {gyro_tol:e})"
        );
        sum_abs_gyro_bias += bias.abs();

        let e = sim
            .sensors()
            .channel_errors(InertialSensor::Accel, i)
            .unwrap();
        let h = Vector3::from(axes[i]).normalize();
        let expected = (1.0 + e.scale_error) * h.dot(&f_b)
            + sim
                .sensors()
                .channel_bias(InertialSensor::Accel, i, t_end)
                .unwrap();
        let measured = avg.accel[i] * a_lsb;
        assert!(
            (measured - expected).abs() < accel_tol,
            "accel {i}: mean {measured} vs {expected} (tol {accel_tol:e})"
        );
    }
    // The turn-on biases are really there (σ 0.05 °/s each), so the check above is not trivially zero.
    assert!(sum_abs_gyro_bias > gyro_tol);

    // Module temperatures: nominal 25 °C, offsets σ 0.3 °C, warm-up of at most 2·(1 − e^{−10/600}).
    for (j, t) in avg.temperatures_c.iter().enumerate() {
        let expected = s.temperature_c + sim.sensors().temperature_delta_c(0.5 * t_end)[j];
        assert!(
            (t - expected).abs() < 0.01,
            "temperature {j}: {t} vs {expected}"
        );
        assert!((t - 25.0).abs() < 5.0 * 0.3 + 0.1);
    }
}

/// Without knowing the drawn errors: the mean must lie within the model's spread around the ideal
/// projection — 5σ of turn-on bias, bias instability, temperature term and scale error.
#[test]
fn averaged_counts_match_ideal_projection_within_model_tolerance() {
    let config = SimConfig {
        scenario: Scenario::Static,
        ..SimConfig::default()
    };
    let axes = block_pyramid_axes();
    let s = &config.sensors;
    let mg = 1e-3 * STANDARD_GRAVITY;
    let n = 2000;
    let root_n = f64::from(n).sqrt();
    let gyro_noise = sample_sigma(
        s.gyro_noise_density_dps_rthz.to_radians(),
        1000.0,
        config.gyro_lsb_rps(),
    ) / root_n;
    let accel_noise = sample_sigma(
        s.accel_noise_density_ug_rthz * 1e-6 * STANDARD_GRAVITY,
        1000.0,
        config.accel_lsb_mps2(),
    ) / root_n;
    // |ΔT| of a module sensor stays below 1 °C here (offset σ 0.3 °C, warm-up over 2 s negligible).
    let gyro_tol = 5.0
        * (s.gyro_turn_on_bias_sigma_dps.powi(2)
            + s.gyro_bias_instability_sigma_dps.powi(2)
            + (s.gyro_bias_temp_coeff_sigma_dps_per_c * 1.0).powi(2))
        .sqrt()
        .to_radians()
        + 5.0 * gyro_noise;
    let accel_tol = 5.0
        * ((s.accel_turn_on_bias_sigma_mg * mg).powi(2)
            + (s.accel_bias_instability_sigma_mg * mg).powi(2)
            + (s.accel_bias_temp_coeff_sigma_mg_per_c * mg).powi(2)
            + (s.accel_scale_error_sigma * STANDARD_GRAVITY).powi(2))
        .sqrt()
        + 5.0 * accel_noise;
    for seed in 0..5 {
        let mut sim = Simulator::new(&config, &axes, &axes, seed).unwrap();
        let avg = run(&mut sim, n as usize);
        for i in 0..4 {
            let h = Vector3::from(axes[i]);
            let measured_gyro = avg.gyro[i] * config.gyro_lsb_rps();
            assert!(
                measured_gyro.abs() < gyro_tol,
                "seed {seed} gyro {i}: {measured_gyro}"
            );
            let ideal = h.dot(&Vector3::new(0.0, 0.0, -STANDARD_GRAVITY));
            let measured = avg.accel[i] * config.accel_lsb_mps2();
            assert!(
                (measured - ideal).abs() < accel_tol,
                "seed {seed} accel {i}: {measured} vs {ideal}"
            );
        }
    }
}

/// The per-sample spread must follow σ = density·√rate (with quantisation): checked at 1 kHz and
/// 4 kHz, where it doubles. The sample standard deviation of n samples has relative σ ≈ 1/√(2n).
#[test]
fn per_sample_noise_scales_with_root_rate() {
    let axes = optimal_pyramid_axes();
    for rate in [1000.0, 4000.0] {
        let config = SimConfig {
            scenario: Scenario::Static,
            imu_rate_hz: rate,
            ..SimConfig::default()
        };
        let mut sim = Simulator::new(&config, &axes, &axes, 3).unwrap();
        let mut out = TickOutput::default();
        let n = 20_000;
        let (mut sum, mut sum2) = (0.0, 0.0);
        for _ in 0..n {
            sim.step(&mut out);
            let Payload::Imu(imu) = out.imu.payload else {
                panic!()
            };
            let x = f64::from(imu.gyro_counts[0]) * config.gyro_lsb_rps();
            sum += x;
            sum2 += x * x;
        }
        let mean = sum / f64::from(n);
        let std = (sum2 / f64::from(n) - mean * mean).sqrt();
        let s = &config.sensors;
        let expected = sample_sigma(
            s.gyro_noise_density_dps_rthz.to_radians(),
            rate,
            config.gyro_lsb_rps(),
        );
        let rel_tol = 5.0 / (2.0 * f64::from(n)).sqrt();
        assert!(
            (std / expected - 1.0).abs() < rel_tol,
            "rate {rate}: σ {std:e} vs {expected:e}"
        );
    }
}
