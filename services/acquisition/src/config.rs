//! `[acquisition]` configuration.

use rins_serial_reader::line_config::SerialLineConfig;
use serde::{Deserialize, Serialize};

/// `[acquisition]` of the configuration: the serial device and how it is read.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct AcquisitionConfig {
    /// Serial device path (a real port, or the simulator's link). `rins up` fills it in for the simulator.
    pub port: Option<String>,
    /// Line speed, baud.
    pub baud: u32,
    /// Longest a read blocks before the loop looks at shutdown and heartbeats again.
    pub read_timeout_ms: u64,
    /// First delay before reopening a missing or lost port; doubles up to `reconnect_max_ms`.
    pub reconnect_initial_ms: u64,
    /// Longest delay between two attempts: a device that comes back is found at most this late.
    pub reconnect_max_ms: u64,
}

impl Default for AcquisitionConfig {
    fn default() -> Self {
        Self {
            port: None,
            baud: 921_600,
            read_timeout_ms: 50,
            reconnect_initial_ms: 10,
            reconnect_max_ms: 1_000,
        }
    }
}

impl AcquisitionConfig {
    /// The serial line's settings, as the reconnecting reader takes them.
    pub fn line(&self) -> SerialLineConfig {
        SerialLineConfig {
            port: self.port.clone(),
            baud: self.baud,
            read_timeout_ms: self.read_timeout_ms,
            reconnect_initial_ms: self.reconnect_initial_ms,
            reconnect_max_ms: self.reconnect_max_ms,
        }
    }

    /// Checks every value's range; the error names the field and the value.
    pub fn validate(&self) -> Result<(), String> {
        self.line().validate("acquisition")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ranges themselves are `SerialLineConfig`'s (and tested there): here, that the fields
    /// reach it and that its errors are named under `acquisition`.
    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert_eq!(AcquisitionConfig::default().validate(), Ok(()));
        let slow_start = AcquisitionConfig {
            reconnect_initial_ms: 5000,
            ..Default::default()
        };
        assert_eq!(
            slow_start.validate().unwrap_err(),
            "acquisition.reconnect_initial_ms = 5000: must be > 0 and <= reconnect_max_ms (1000)"
        );
    }
}
