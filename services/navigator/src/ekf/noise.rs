//! Process noise and initial uncertainty of the error filter.

use serde::{Deserialize, Serialize};

/// Noise densities of the inertial sensors as the filter models them, and the initial standard
/// deviations of the error state. Densities are per √Hz, so that a sample of length Δt adds
/// `density² Δt` of variance whatever the rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EkfNoise {
    /// Angle random walk, rad/s/√Hz.
    pub gyro_noise_density: f64,
    /// Velocity random walk, m/s²/√Hz.
    pub accel_noise_density: f64,
    /// Gyro bias random walk, rad/s²/√Hz.
    pub gyro_bias_walk: f64,
    /// Accelerometer bias random walk, m/s³/√Hz.
    pub accel_bias_walk: f64,
    /// Initial roll/pitch σ, rad.
    pub initial_tilt_sigma: f64,
    /// Initial heading σ, rad.
    pub initial_heading_sigma: f64,
    /// Initial velocity σ, m/s.
    pub initial_velocity_sigma: f64,
    /// Initial position σ, m.
    pub initial_position_sigma: f64,
    /// Initial gyro bias σ, rad/s.
    pub initial_gyro_bias_sigma: f64,
    /// Initial accelerometer bias σ, m/s².
    pub initial_accel_bias_sigma: f64,
}

impl Default for EkfNoise {
    /// A MEMS unit of the product's class (0.01 °/s/√Hz, 150 µg/√Hz) with margins for
    /// the unmodelled scale-factor and vibration errors.
    fn default() -> Self {
        Self {
            gyro_noise_density: 0.05_f64.to_radians(),
            accel_noise_density: 0.01,
            gyro_bias_walk: 1e-5,
            accel_bias_walk: 1e-4,
            initial_tilt_sigma: 1.0_f64.to_radians(),
            initial_heading_sigma: 10.0_f64.to_radians(),
            initial_velocity_sigma: 0.1,
            initial_position_sigma: 1.0,
            initial_gyro_bias_sigma: 0.1_f64.to_radians(),
            initial_accel_bias_sigma: 0.05,
        }
    }
}

impl EkfNoise {
    /// The error-state variances a filter starts with: the initial σs squared, per block of the
    /// error state, the heading its own.
    pub fn initial_variances(&self) -> [f64; super::STATES] {
        let mut v = [0.0; super::STATES];
        let blocks = [
            (super::ATT, self.initial_tilt_sigma),
            (super::VEL, self.initial_velocity_sigma),
            (super::POS, self.initial_position_sigma),
            (super::BG, self.initial_gyro_bias_sigma),
            (super::BA, self.initial_accel_bias_sigma),
        ];
        for (start, sigma) in blocks {
            v[start..start + 3].fill(sigma * sigma);
        }
        v[super::ATT + 2] = self.initial_heading_sigma.powi(2);
        v
    }

    /// Every value must be finite and positive: `(field, value)` of the first that is not.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        let fields = [
            ("gyro_noise_density", self.gyro_noise_density),
            ("accel_noise_density", self.accel_noise_density),
            ("gyro_bias_walk", self.gyro_bias_walk),
            ("accel_bias_walk", self.accel_bias_walk),
            ("initial_tilt_sigma", self.initial_tilt_sigma),
            ("initial_heading_sigma", self.initial_heading_sigma),
            ("initial_velocity_sigma", self.initial_velocity_sigma),
            ("initial_position_sigma", self.initial_position_sigma),
            ("initial_gyro_bias_sigma", self.initial_gyro_bias_sigma),
            ("initial_accel_bias_sigma", self.initial_accel_bias_sigma),
        ];
        match fields
            .into_iter()
            .find(|(_, v)| !(v.is_finite() && *v > 0.0))
        {
            Some(bad) => Err(bad),
            None => Ok(()),
        }
    }
}
