//! Shared test fixtures.
#![allow(dead_code)]

use rins_sim::{SensorModelConfig, SimConfig};

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
