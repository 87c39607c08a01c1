//! Faults that can be injected into one inertial channel while the simulation runs.

use crate::error::SimError;

/// Which kind of inertial channel a fault addresses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InertialSensor {
    /// A single-axis rate gyro (rad/s).
    Gyro,
    /// A single-axis accelerometer (m/s², specific force).
    Accel,
}

impl InertialSensor {
    /// Lower-case name used in errors.
    pub fn name(self) -> &'static str {
        match self {
            InertialSensor::Gyro => "gyro",
            InertialSensor::Accel => "accel",
        }
    }
}

/// A channel fault. Magnitudes are in the channel's SI unit (rad/s for gyros, m/s² for accels).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ChannelFault {
    /// No data: the channel's valid bit is cleared and its counts read 0.
    Dead,
    /// The counts freeze at the last value output before the fault.
    Stuck,
    /// A constant bias is added.
    BiasStep {
        /// Bias added to every sample, rad/s or m/s².
        bias: f64,
    },
    /// A bias growing linearly from zero at injection time is added.
    Ramp {
        /// Growth of the bias, rad/s or m/s² per second of device time.
        rate_per_s: f64,
    },
    /// Extra white noise of this σ per sample is added.
    NoiseBurst {
        /// σ per sample of the added noise, rad/s or m/s².
        sigma: f64,
    },
    /// The channel reads positive full scale and reports saturation.
    Saturated,
    /// Dead for the first `dropout_s` of every `period_s`, counted from injection.
    Intermittent {
        /// Length of one dead-then-alive cycle, s.
        period_s: f64,
        /// Dead time at the start of each cycle, s; 0 to `period_s`.
        dropout_s: f64,
    },
}

impl ChannelFault {
    /// Checks the fault's parameters.
    pub fn validate(&self) -> Result<(), SimError> {
        let bad = |field: &'static str, value: f64, reason: &'static str| {
            Err(SimError::Fault {
                field,
                value: value.to_string(),
                reason,
            })
        };
        match *self {
            ChannelFault::BiasStep { bias } if !bias.is_finite() => {
                bad("bias", bias, "must be finite")
            }
            ChannelFault::Ramp { rate_per_s } if !rate_per_s.is_finite() => {
                bad("rate_per_s", rate_per_s, "must be finite")
            }
            ChannelFault::NoiseBurst { sigma } if !(sigma.is_finite() && sigma >= 0.0) => {
                bad("sigma", sigma, "must be finite and >= 0")
            }
            ChannelFault::Intermittent { period_s, .. }
                if !(period_s.is_finite() && period_s > 0.0) =>
            {
                bad("period_s", period_s, "must be finite and > 0")
            }
            ChannelFault::Intermittent {
                period_s,
                dropout_s,
            } if !(dropout_s.is_finite() && (0.0..=period_s).contains(&dropout_s)) => {
                bad("dropout_s", dropout_s, "must be within 0..=period_s")
            }
            _ => Ok(()),
        }
    }
}

/// A fault in effect on one channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ActiveFault {
    pub fault: ChannelFault,
    pub start_s: f64,
    /// Counts output just before injection (for [`ChannelFault::Stuck`]).
    pub frozen_counts: i16,
}
