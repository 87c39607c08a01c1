//! Error-model parameters of the simulated sensor block (defaults: small-UAV MEMS block).

use serde::{Deserialize, Serialize};

use crate::error::{SimError, check_positive, check_range};
use rins_earth::STANDARD_GRAVITY;

/// The converter is the protocol's: signed 12-bit counts.
pub use rins_protocol::layout::{
    COUNT_MAX as ADC_MAX, COUNT_MIN as ADC_MIN, COUNTS_PER_FULL_SCALE as ADC_HALF_RANGE,
};
/// Module temperature sensors the frame can carry.
pub const MAX_TEMPERATURE_SENSORS: u8 = ipc_types::MAX_TEMPERATURES as u8;

/// Per-channel error model of gyros and accelerometers, module temperatures, barometer,
/// magnetometer and foot-pressure noise. Units are in the field names; degrees and g only here.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensorModelConfig {
    /// Gyro full scale: ±this maps to ±2048 counts, °/s. Not a key of `[sim.sensors]`: the simulated
    /// block has the converters of `[device]`, set by whoever builds the simulator.
    #[serde(skip)]
    pub gyro_full_scale_dps: f64,
    /// Gyro white-noise density (angle random walk), °/s/√Hz.
    pub gyro_noise_density_dps_rthz: f64,
    /// σ of the constant bias drawn at turn-on, °/s.
    pub gyro_turn_on_bias_sigma_dps: f64,
    /// Stationary σ of the first-order Gauss–Markov bias (bias instability), °/s.
    pub gyro_bias_instability_sigma_dps: f64,
    /// Correlation time of the Gauss–Markov bias, s.
    pub gyro_bias_instability_tau_s: f64,
    /// σ of the scale-factor error (fraction, 0.001 = 0.1 %).
    pub gyro_scale_error_sigma: f64,
    /// σ of the per-channel bias temperature coefficient, °/s per °C.
    pub gyro_bias_temp_coeff_sigma_dps_per_c: f64,

    /// Accelerometer full scale: ±this maps to ±2048 counts, g (9.80665 m/s²). Set from `[device]`,
    /// like `gyro_full_scale_dps`.
    #[serde(skip)]
    pub accel_full_scale_g: f64,
    /// Accelerometer white-noise density (velocity random walk), µg/√Hz.
    pub accel_noise_density_ug_rthz: f64,
    /// σ of the constant bias drawn at turn-on, mg.
    pub accel_turn_on_bias_sigma_mg: f64,
    /// Stationary σ of the Gauss–Markov bias, mg.
    pub accel_bias_instability_sigma_mg: f64,
    /// Correlation time of the accelerometer Gauss–Markov bias, s.
    pub accel_bias_instability_tau_s: f64,
    /// σ of the accelerometer scale-factor error (fraction).
    pub accel_scale_error_sigma: f64,
    /// σ of the per-channel bias temperature coefficient, mg per °C.
    pub accel_bias_temp_coeff_sigma_mg_per_c: f64,

    /// σ of the angle between each channel's true and nominal sensing axis, mrad.
    pub axis_misalignment_sigma_mrad: f64,

    /// Module temperature sensors reported (1..=4); channel i follows sensor i mod this.
    pub temperature_sensors: u8,
    /// Nominal module temperature, and the reference of the bias temperature coefficients, °C.
    pub temperature_c: f64,
    /// σ of each sensor's offset from the nominal temperature, °C.
    pub temperature_spread_c: f64,
    /// Temperature rise during warm-up (first-order approach), °C.
    pub temperature_warmup_c: f64,
    /// Warm-up time constant, s.
    pub temperature_warmup_tau_s: f64,

    /// Barometer white noise σ per sample, Pa.
    pub baro_noise_pa: f64,

    /// Magnetometer white noise σ per axis and sample, µT.
    pub mag_noise_ut: f64,
    /// Hard-iron offset added in the body frame, µT.
    pub mag_hard_iron_ut: [f64; 3],
    /// Soft-iron matrix applied to the body-frame field (row-major), dimensionless.
    pub mag_soft_iron: [[f64; 3]; 3],

    /// Foot-pressure sensor white noise σ, raw counts (the reading is clamped to 0..=65535).
    pub foot_pressure_noise_counts: f64,
}

impl Default for SensorModelConfig {
    fn default() -> Self {
        Self {
            gyro_full_scale_dps: 300.0,
            gyro_noise_density_dps_rthz: 0.01,
            gyro_turn_on_bias_sigma_dps: 0.05,
            gyro_bias_instability_sigma_dps: 0.002,
            gyro_bias_instability_tau_s: 300.0,
            gyro_scale_error_sigma: 0.001,
            gyro_bias_temp_coeff_sigma_dps_per_c: 0.001,
            accel_full_scale_g: 8.0,
            accel_noise_density_ug_rthz: 150.0,
            accel_turn_on_bias_sigma_mg: 5.0,
            accel_bias_instability_sigma_mg: 0.05,
            accel_bias_instability_tau_s: 300.0,
            accel_scale_error_sigma: 0.001,
            accel_bias_temp_coeff_sigma_mg_per_c: 0.05,
            axis_misalignment_sigma_mrad: 0.0,
            temperature_sensors: MAX_TEMPERATURE_SENSORS,
            temperature_c: 25.0,
            temperature_spread_c: 0.3,
            temperature_warmup_c: 2.0,
            temperature_warmup_tau_s: 600.0,
            baro_noise_pa: 2.0,
            mag_noise_ut: 0.1,
            mag_hard_iron_ut: [0.0; 3],
            mag_soft_iron: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            foot_pressure_noise_counts: 20.0,
        }
    }
}

impl SensorModelConfig {
    /// Gyro ADC resolution: rad/s per count.
    pub fn gyro_lsb_rps(&self) -> f64 {
        self.gyro_full_scale_dps.to_radians() / ADC_HALF_RANGE
    }

    /// Accelerometer ADC resolution: m/s² per count.
    pub fn accel_lsb_mps2(&self) -> f64 {
        self.accel_full_scale_g * STANDARD_GRAVITY / ADC_HALF_RANGE
    }

    /// Checks every field; the error names the field (prefixed `sim.sensors.`) and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        const NON_NEG: &str = "must be finite and >= 0";
        const SIGMA_MAX: f64 = 1e6;
        check_positive(
            "sim.sensors.gyro_full_scale_dps",
            self.gyro_full_scale_dps,
            1e5,
            "must be > 0 and <= 100000",
        )?;
        check_positive(
            "sim.sensors.accel_full_scale_g",
            self.accel_full_scale_g,
            1e4,
            "must be > 0 and <= 10000",
        )?;
        let non_negative = [
            (
                "sim.sensors.gyro_noise_density_dps_rthz",
                self.gyro_noise_density_dps_rthz,
            ),
            (
                "sim.sensors.gyro_turn_on_bias_sigma_dps",
                self.gyro_turn_on_bias_sigma_dps,
            ),
            (
                "sim.sensors.gyro_bias_instability_sigma_dps",
                self.gyro_bias_instability_sigma_dps,
            ),
            (
                "sim.sensors.gyro_scale_error_sigma",
                self.gyro_scale_error_sigma,
            ),
            (
                "sim.sensors.gyro_bias_temp_coeff_sigma_dps_per_c",
                self.gyro_bias_temp_coeff_sigma_dps_per_c,
            ),
            (
                "sim.sensors.accel_noise_density_ug_rthz",
                self.accel_noise_density_ug_rthz,
            ),
            (
                "sim.sensors.accel_turn_on_bias_sigma_mg",
                self.accel_turn_on_bias_sigma_mg,
            ),
            (
                "sim.sensors.accel_bias_instability_sigma_mg",
                self.accel_bias_instability_sigma_mg,
            ),
            (
                "sim.sensors.accel_scale_error_sigma",
                self.accel_scale_error_sigma,
            ),
            (
                "sim.sensors.accel_bias_temp_coeff_sigma_mg_per_c",
                self.accel_bias_temp_coeff_sigma_mg_per_c,
            ),
            (
                "sim.sensors.axis_misalignment_sigma_mrad",
                self.axis_misalignment_sigma_mrad,
            ),
            (
                "sim.sensors.temperature_spread_c",
                self.temperature_spread_c,
            ),
            ("sim.sensors.baro_noise_pa", self.baro_noise_pa),
            ("sim.sensors.mag_noise_ut", self.mag_noise_ut),
            (
                "sim.sensors.foot_pressure_noise_counts",
                self.foot_pressure_noise_counts,
            ),
        ];
        for (field, value) in non_negative {
            check_range(field, value, 0.0, SIGMA_MAX, NON_NEG)?;
        }
        check_positive(
            "sim.sensors.gyro_bias_instability_tau_s",
            self.gyro_bias_instability_tau_s,
            1e9,
            "must be > 0",
        )?;
        check_positive(
            "sim.sensors.accel_bias_instability_tau_s",
            self.accel_bias_instability_tau_s,
            1e9,
            "must be > 0",
        )?;
        check_positive(
            "sim.sensors.temperature_warmup_tau_s",
            self.temperature_warmup_tau_s,
            1e9,
            "must be > 0",
        )?;
        if !(1..=MAX_TEMPERATURE_SENSORS).contains(&self.temperature_sensors) {
            return Err(SimError::config(
                "sim.sensors.temperature_sensors",
                self.temperature_sensors,
                "must be 1..=4",
            ));
        }
        // The frame carries hundredths of a degree in an i16: keep well inside ±327 °C.
        check_range(
            "sim.sensors.temperature_c",
            self.temperature_c,
            -55.0,
            125.0,
            "must be -55..=125",
        )?;
        check_range(
            "sim.sensors.temperature_warmup_c",
            self.temperature_warmup_c,
            -50.0,
            50.0,
            "must be -50..=50",
        )?;
        check_mag_distortion(
            ("sim.sensors.mag_hard_iron_ut", &self.mag_hard_iron_ut),
            ("sim.sensors.mag_soft_iron", &self.mag_soft_iron),
        )
    }
}

/// Checks a magnetometer's hard iron (µT) and soft-iron matrix, each given with its field name:
/// finite, and small enough that the readings stay far inside the frame's i32 nanotesla.
pub(crate) fn check_mag_distortion(
    hard_iron_ut: (&'static str, &[f64; 3]),
    soft_iron: (&'static str, &[[f64; 3]; 3]),
) -> Result<(), SimError> {
    for value in hard_iron_ut.1 {
        check_range(
            hard_iron_ut.0,
            *value,
            -1e4,
            1e4,
            "components must be finite, |x| <= 10000",
        )?;
    }
    for value in soft_iron.1.iter().flatten() {
        check_range(
            soft_iron.0,
            *value,
            -10.0,
            10.0,
            "components must be finite, |x| <= 10",
        )?;
    }
    Ok(())
}
