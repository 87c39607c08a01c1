//! `[sim.gnss]`: the simulated GNSS receiver — its rate, noise, latency and protocol.

use serde::{Deserialize, Serialize};

/// The receiver's output protocol.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ReceiverProtocol {
    /// NMEA 0183 GGA, RMC, GST and VTG per epoch.
    Nmea,
    /// u-blox UBX NAV-PVT per epoch.
    Ubx,
}

/// `[sim.gnss]` of the configuration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GnssReceiverConfig {
    /// Simulate a receiver (also turned on by `rins sim --gnss-link` and `rins up --gnss`).
    pub enabled: bool,
    /// Epochs per second.
    pub rate_hz: f64,
    /// White position noise, σ per horizontal axis, m (also the accuracy the receiver reports).
    pub sigma_horizontal_m: f64,
    /// White position noise, vertical σ, m.
    pub sigma_vertical_m: f64,
    /// White velocity noise, σ per axis, m/s.
    pub sigma_velocity_mps: f64,
    /// From the instant an epoch measures to its last byte on the line, s.
    pub latency_s: f64,
    /// Output protocol.
    pub protocol: ReceiverProtocol,
    /// Antenna position relative to the IMU, body FRD, m.
    pub lever_arm_m: [f64; 3],
}

impl Default for GnssReceiverConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            rate_hz: 5.0,
            sigma_horizontal_m: 1.5,
            sigma_vertical_m: 3.0,
            sigma_velocity_mps: 0.1,
            latency_s: 0.08,
            protocol: ReceiverProtocol::Nmea,
            lever_arm_m: [0.0; 3],
        }
    }
}

impl GnssReceiverConfig {
    /// Checks every value; the error names the field and the value.
    pub fn validate(&self, imu_rate_hz: f64) -> Result<(), String> {
        let bad =
            |field: &str, value: f64, why: &str| Err(format!("sim.gnss.{field} = {value}: {why}"));
        if !(self.rate_hz.is_finite()
            && self.rate_hz > 0.0
            && self.rate_hz <= 20.0_f64.min(imu_rate_hz))
        {
            return bad(
                "rate_hz",
                self.rate_hz,
                "must be > 0 and <= 20 (and the IMU rate)",
            );
        }
        for (field, sigma) in [
            ("sigma_horizontal_m", self.sigma_horizontal_m),
            ("sigma_vertical_m", self.sigma_vertical_m),
            ("sigma_velocity_mps", self.sigma_velocity_mps),
        ] {
            if !(sigma.is_finite() && (0.0..=1000.0).contains(&sigma)) {
                return bad(field, sigma, "must be >= 0 and <= 1000");
            }
        }
        if !(self.latency_s.is_finite() && (0.0..=1.0).contains(&self.latency_s)) {
            return bad("latency_s", self.latency_s, "must be >= 0 and <= 1 s");
        }
        for (k, x) in self.lever_arm_m.iter().enumerate() {
            if !(x.is_finite() && x.abs() <= 100.0) {
                return bad(&format!("lever_arm_m[{k}]"), *x, "must be within ±100 m");
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert!(GnssReceiverConfig::default().validate(1000.0).is_ok());
        let bad = GnssReceiverConfig {
            rate_hz: 50.0,
            ..Default::default()
        };
        assert!(
            bad.validate(1000.0)
                .unwrap_err()
                .starts_with("sim.gnss.rate_hz = 50")
        );
        let bad = GnssReceiverConfig {
            latency_s: -0.1,
            ..Default::default()
        };
        assert!(
            bad.validate(1000.0)
                .unwrap_err()
                .contains("latency_s = -0.1")
        );
        let bad = GnssReceiverConfig {
            lever_arm_m: [0.0, f64::NAN, 0.0],
            ..Default::default()
        };
        assert!(bad.validate(1000.0).unwrap_err().contains("lever_arm_m[1]"));
    }
}
