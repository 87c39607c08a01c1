//! The settings of one serial line: which device, at what speed, how long a read blocks, and how
//! the reopening backs off. Each service that reads a line embeds these under its own section.

use std::time::Duration;

use crate::backoff::Backoff;

/// A serial line's device and how it is read and reopened.
#[derive(Debug, Clone, PartialEq)]
pub struct SerialLineConfig {
    /// Serial device path; `None` until configured (`rins up` fills it in for the simulator).
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

impl SerialLineConfig {
    /// Checks every value's range; the error names the field under `section` (the configuration
    /// table the line belongs to) and the value.
    pub fn validate(&self, section: &str) -> Result<(), String> {
        if self.baud == 0 {
            return Err(format!("{section}.baud = 0: must be > 0"));
        }
        if !(1..=10_000).contains(&self.read_timeout_ms) {
            return Err(format!(
                "{section}.read_timeout_ms = {}: must be in 1..=10000",
                self.read_timeout_ms
            ));
        }
        if self.reconnect_initial_ms == 0 || self.reconnect_initial_ms > self.reconnect_max_ms {
            return Err(format!(
                "{section}.reconnect_initial_ms = {}: must be > 0 and <= reconnect_max_ms ({})",
                self.reconnect_initial_ms, self.reconnect_max_ms
            ));
        }
        if let Some(port) = &self.port
            && port.is_empty()
        {
            return Err(format!("{section}.port = \"\": must name a device path"));
        }
        Ok(())
    }

    /// Longest a read blocks.
    pub fn read_timeout(&self) -> Duration {
        Duration::from_millis(self.read_timeout_ms)
    }

    /// The backoff between attempts to open the device.
    pub fn backoff(&self) -> Backoff {
        Backoff::new(
            Duration::from_millis(self.reconnect_initial_ms),
            Duration::from_millis(self.reconnect_max_ms),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn line() -> SerialLineConfig {
        SerialLineConfig {
            port: None,
            baud: 115_200,
            read_timeout_ms: 50,
            reconnect_initial_ms: 10,
            reconnect_max_ms: 1_000,
        }
    }

    #[test]
    fn each_bad_value_is_named_under_its_section() {
        assert!(line().validate("s").is_ok());
        let cases = [
            (
                SerialLineConfig { baud: 0, ..line() },
                "s.baud = 0: must be > 0",
            ),
            (
                SerialLineConfig {
                    read_timeout_ms: 0,
                    ..line()
                },
                "s.read_timeout_ms = 0: must be in 1..=10000",
            ),
            (
                SerialLineConfig {
                    reconnect_initial_ms: 5000,
                    ..line()
                },
                "s.reconnect_initial_ms = 5000: must be > 0 and <= reconnect_max_ms (1000)",
            ),
            (
                SerialLineConfig {
                    port: Some(String::new()),
                    ..line()
                },
                "s.port = \"\": must name a device path",
            ),
        ];
        for (config, message) in cases {
            assert_eq!(config.validate("s").unwrap_err(), message);
        }
    }

    #[test]
    fn timeout_and_backoff_come_from_the_milliseconds() {
        let l = line();
        assert_eq!(l.read_timeout(), Duration::from_millis(50));
        let b = l.backoff();
        assert_eq!(
            (b.initial(), b.max()),
            (Duration::from_millis(10), Duration::from_millis(1000))
        );
    }
}
