//! `[sim.calibration]`: the `calibrate` scenario's motion and the magnetometer distortion it
//! carries, so `rins calibrate mag` has something to find.

use serde::{Deserialize, Serialize};

use crate::error::{SimError, check_range};
use crate::sensor_model::SensorModelConfig;
use crate::sensor_model::config::check_mag_distortion;

/// Shortest accepted yaw turn, s: a faster turn (over 216 °/s) nears the 300 °/s gyro full scale.
pub const MIN_SWEEP_S: f64 = 2.0;

/// The calibrate scenario's settings.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct CalibrationConfig {
    /// Time of one full yaw turn, s; a cycle of eight turns and the tilts between them lasts
    /// 11.3 times this (68 s at the default 6 s).
    pub sweep_s: f64,
    /// Hard-iron offset of the magnetometer in this scenario, µT (replaces
    /// `sim.sensors.mag_hard_iron_ut`).
    pub hard_iron_ut: [f64; 3],
    /// Soft-iron matrix of the magnetometer in this scenario, row-major (replaces
    /// `sim.sensors.mag_soft_iron`). The default is symmetric: the symmetric correction
    /// `rins calibrate mag` fits is then exactly its inverse.
    pub soft_iron: [[f64; 3]; 3],
}

impl Default for CalibrationConfig {
    fn default() -> Self {
        Self {
            sweep_s: 6.0,
            // A few µT: what a motor or a battery near the magnetometer typically adds.
            hard_iron_ut: [5.0, -3.0, 2.0],
            // A few per cent off identity.
            soft_iron: [
                [1.04, 0.02, -0.01],
                [0.02, 0.97, 0.015],
                [-0.01, 0.015, 1.02],
            ],
        }
    }
}

impl CalibrationConfig {
    /// Checks every field; the error names the field (`sim.calibration.…`) and its value.
    pub fn validate(&self) -> Result<(), SimError> {
        check_range(
            "sim.calibration.sweep_s",
            self.sweep_s,
            MIN_SWEEP_S,
            3600.0,
            "must be within 2..=3600",
        )?;
        check_mag_distortion(
            ("sim.calibration.hard_iron_ut", &self.hard_iron_ut),
            ("sim.calibration.soft_iron", &self.soft_iron),
        )
    }

    /// `sensors` with this scenario's magnetometer distortion in place of its own.
    pub fn distort(&self, sensors: &SensorModelConfig) -> SensorModelConfig {
        SensorModelConfig {
            mag_hard_iron_ut: self.hard_iron_ut,
            mag_soft_iron: self.soft_iron,
            ..sensors.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_distort_only_the_magnetometer() {
        let c = CalibrationConfig::default();
        c.validate().unwrap();
        let plain = SensorModelConfig::default();
        let distorted = c.distort(&plain);
        assert_eq!(distorted.mag_hard_iron_ut, [5.0, -3.0, 2.0]);
        assert_eq!(distorted.mag_soft_iron[1][1], 0.97);
        let undone = SensorModelConfig {
            mag_hard_iron_ut: plain.mag_hard_iron_ut,
            mag_soft_iron: plain.mag_soft_iron,
            ..distorted
        };
        assert_eq!(undone, plain);
    }

    #[test]
    fn bad_values_name_the_field() {
        let fast = CalibrationConfig {
            sweep_s: 1.0,
            ..CalibrationConfig::default()
        };
        let err = fast.validate().unwrap_err().to_string();
        assert!(err.contains("sim.calibration.sweep_s = 1"), "{err}");
        let mut iron = CalibrationConfig::default();
        iron.soft_iron[2][0] = f64::NAN;
        let err = iron.validate().unwrap_err().to_string();
        assert!(err.contains("sim.calibration.soft_iron = NaN"), "{err}");
    }
}
