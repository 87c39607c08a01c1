//! Errors raised while building a simulator from configuration.

use thiserror::Error;

/// Why a simulator (or one of its parts) could not be built.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SimError {
    /// A configuration value is out of its allowed range.
    #[error("{field} = {value}: {reason}")]
    Config {
        /// Dotted path of the field, e.g. `sim.imu_rate_hz`.
        field: &'static str,
        /// The offending value as written.
        value: String,
        /// What the value must satisfy.
        reason: &'static str,
    },
    /// A `[sim.gnss]` value is out of range (the message names the field and the value).
    #[error("{0}")]
    GnssReceiver(String),
    /// A sensor axis list has an unsupported number of channels.
    #[error("{kind} axes: {count} channels given: must be 3..=16")]
    AxisCount {
        /// `gyro` or `accel`.
        kind: &'static str,
        /// Number of axes given.
        count: usize,
    },
    /// One sensor axis is not a usable direction.
    #[error("{kind} axis {index} = {axis:?}: {reason}")]
    Axis {
        /// `gyro` or `accel`.
        kind: &'static str,
        /// Channel index.
        index: usize,
        /// The axis as given.
        axis: [f64; 3],
        /// What the axis must satisfy.
        reason: &'static str,
    },
    /// A fault was addressed to a channel that does not exist.
    #[error("{kind} channel {channel}: no such channel (device has {count})")]
    NoSuchChannel {
        /// `gyro` or `accel`.
        kind: &'static str,
        /// Requested channel.
        channel: usize,
        /// Channels present.
        count: usize,
    },
    /// A fault's parameters are invalid.
    #[error("fault {field} = {value}: {reason}")]
    Fault {
        /// Name of the fault parameter.
        field: &'static str,
        /// The offending value.
        value: String,
        /// What the value must satisfy.
        reason: &'static str,
    },
}

impl SimError {
    pub(crate) fn config(
        field: &'static str,
        value: impl std::fmt::Display,
        reason: &'static str,
    ) -> Self {
        SimError::Config {
            field,
            value: value.to_string(),
            reason,
        }
    }
}

/// Checks `value` is finite and inside `[min, max]`.
pub(crate) fn check_range(
    field: &'static str,
    value: f64,
    min: f64,
    max: f64,
    reason: &'static str,
) -> Result<(), SimError> {
    if value.is_finite() && value >= min && value <= max {
        Ok(())
    } else {
        Err(SimError::config(field, value, reason))
    }
}

/// Checks `value` is finite and strictly positive (and not above `max`).
pub(crate) fn check_positive(
    field: &'static str,
    value: f64,
    max: f64,
    reason: &'static str,
) -> Result<(), SimError> {
    if value.is_finite() && value > 0.0 && value <= max {
        Ok(())
    } else {
        Err(SimError::config(field, value, reason))
    }
}
