//! `[gnss]` configuration: whether a receiver is fitted, and its serial line.

use std::time::Duration;

use rins_serial_reader::line_config::SerialLineConfig;
use serde::{Deserialize, Serialize};

/// `[gnss]` of the configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct GnssConfig {
    /// A receiver is fitted: the watchdog runs the gnss service.
    pub enabled: bool,
    /// The receiver's serial device; `rins up` sets it to the simulated receiver.
    pub port: Option<String>,
    /// Line speed, baud.
    pub baud: u32,
    /// Longest a read blocks before the loop looks at shutdown and heartbeats again.
    pub read_timeout_ms: u64,
    /// First delay before reopening a missing or lost port; doubles up to `reconnect_max_ms`.
    pub reconnect_initial_ms: u64,
    /// Longest delay between two attempts.
    pub reconnect_max_ms: u64,
    /// The line counts as quiet (heartbeat `input_stale`) after this long without a byte.
    pub stale_after_ms: u64,
}

impl Default for GnssConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            port: None,
            baud: 115_200,
            read_timeout_ms: 50,
            reconnect_initial_ms: 10,
            reconnect_max_ms: 1_000,
            stale_after_ms: 1_000,
        }
    }
}

impl GnssConfig {
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

    /// How long without a byte makes the line quiet.
    pub fn stale_after(&self) -> Duration {
        Duration::from_millis(self.stale_after_ms)
    }

    /// Checks every value's range; the error names the field and the value.
    pub fn validate(&self) -> Result<(), String> {
        self.line().validate("gnss")?;
        if !(100..=60_000).contains(&self.stale_after_ms) {
            return Err(format!(
                "gnss.stale_after_ms = {}: must be in 100..=60000",
                self.stale_after_ms
            ));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The serial line's ranges are `SerialLineConfig`'s (and tested there): here, that its
    /// errors are named under `gnss`, and the receiver's own staleness bound.
    #[test]
    fn defaults_are_valid_and_bad_values_are_named_under_gnss() {
        let refusal = |c: GnssConfig| c.validate().err();
        assert_eq!(refusal(GnssConfig::default()), None);
        let no_baud = GnssConfig {
            baud: 0,
            ..Default::default()
        };
        let empty_port = GnssConfig {
            port: Some(String::new()),
            ..Default::default()
        };
        let hasty = GnssConfig {
            stale_after_ms: 5,
            ..Default::default()
        };
        for (config, message) in [
            (no_baud, "gnss.baud = 0: must be > 0"),
            (empty_port, "gnss.port = \"\": must name a device path"),
            (hasty, "gnss.stale_after_ms = 5: must be in 100..=60000"),
        ] {
            assert_eq!(refusal(config).as_deref(), Some(message));
        }
    }
}
