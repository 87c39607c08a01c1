//! Shared test fixtures.
#![allow(dead_code)]

use rins_sim::{SensorModelConfig, SimConfig};

/// The 4-face pyramid of docs/design.md §4: β_i = 45° + i·90°, elevation α.
pub fn pyramid(alpha_deg: f64) -> Vec<[f64; 3]> {
    let a = alpha_deg.to_radians();
    (0..4)
        .map(|i| {
            let b = (45.0 + 90.0 * f64::from(i)).to_radians();
            [a.cos() * b.cos(), a.cos() * b.sin(), a.sin()]
        })
        .collect()
}

/// Optimal 4-sensor pyramid (HᵀH = 4/3 I).
pub fn optimal_pyramid() -> Vec<[f64; 3]> {
    pyramid(35.264_389_682_754_654)
}

/// A sensor model with every random error and noise switched off.
pub fn noiseless_sensors() -> SensorModelConfig {
    SensorModelConfig {
        gyro_noise_density_dps_rthz: 0.0,
        gyro_turn_on_bias_sigma_dps: 0.0,
        gyro_bias_instability_sigma_dps: 0.0,
        gyro_scale_error_sigma: 0.0,
        gyro_bias_temp_coeff_sigma_dps_per_c: 0.0,
        accel_noise_density_ug_rthz: 0.0,
        accel_turn_on_bias_sigma_mg: 0.0,
        accel_bias_instability_sigma_mg: 0.0,
        accel_scale_error_sigma: 0.0,
        accel_bias_temp_coeff_sigma_mg_per_c: 0.0,
        baro_noise_pa: 0.0,
        mag_noise_ut: 0.0,
        foot_pressure_noise_counts: 0.0,
        ..SensorModelConfig::default()
    }
}

/// Default configuration with the given scenario.
pub fn config(scenario: rins_sim::Scenario) -> SimConfig {
    SimConfig {
        scenario,
        ..SimConfig::default()
    }
}
