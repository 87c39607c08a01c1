//! Fusion's output: body rate and specific force fused from the redundant channels, with the
//! state of every channel, why it is not Ok, and the solution's flags.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::{Header, MAX_CHANNELS, PAYLOAD_VERSION};

wire_enum! {
    /// State of one redundant channel as judged by fusion ([`FusedImu::gyro_state`],
    /// [`FusedImu::accel_state`]).
    #[derive(Default)]
    pub enum ChannelState: u8 {
        /// In the solution, no fault suspected.
        #[default]
        Ok = 0 => "ok",
        /// In doubt (see [`FaultReason`]) but still fused: a fault was detected without being
        /// isolated to one channel, or the channel reads a genuine over-range.
        Suspect = 1 => "suspect",
        /// Left out of the solution; the exclusion latches until the channel is re-admitted.
        Excluded = 2 => "excluded",
        /// Not fitted in this sensor block.
        Absent = 3 => "absent",
    }
}

wire_enum! {
    /// Why a channel is suspect or excluded ([`FusedImu::gyro_reason`], [`FusedImu::accel_reason`]).
    #[derive(Default)]
    pub enum FaultReason: u8 {
        /// No fault: the channel is Ok (or absent).
        #[default]
        None = 0 => "none",
        /// The device flagged the channel invalid, or its samples stopped arriving.
        Missing = 1 => "missing",
        /// The device reported an error for the channel's module.
        DeviceError = 2 => "device-error",
        /// The channel sits at the end of the converter range.
        Saturated = 3 => "saturated",
        /// The channel's value froze while the others varied.
        Stuck = 4 => "stuck",
        /// The channel's noise is far above its peers'.
        Noisy = 5 => "noisy",
        /// Isolated by the parity test (generalised likelihood test).
        Parity = 6 => "parity",
        /// Isolated against the gravity / zero-rate reference while stationary.
        StationaryReference = 7 => "stationary-reference",
        /// The module's temperature is outside the calibrated range.
        Temperature = 8 => "temperature",
    }
}

/// Body rate and specific force fused from the redundant channels, published by fusion for every
/// raw IMU frame; the navigator integrates it.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FusedImu")]
pub struct FusedImu {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Gyro channels fitted: entries of [`FusedImu::gyro_state`] that describe a channel.
    pub n_gyro: u8,
    /// Accelerometer channels fitted: entries of [`FusedImu::accel_state`] that describe a
    /// channel.
    pub n_accel: u8,
    /// Bits of [`fused_flags`]: whether the solution is valid, and why not.
    pub flags: u32,
    /// The raw frame's header, with fusion's publish time stamped.
    pub header: Header,
    /// Body rate, FRD, rad/s.
    pub rate_rps: [f64; 3],
    /// Specific force, FRD, m/s².
    pub specific_force_mps2: [f64; 3],
    /// Variance of each rate axis, (rad/s)².
    pub rate_var: [f64; 3],
    /// Variance of each specific-force axis, (m/s²)².
    pub specific_force_var: [f64; 3],
    /// Per gyro channel, [`ChannelState`] as u8.
    pub gyro_state: [u8; MAX_CHANNELS],
    /// Per accelerometer channel, [`ChannelState`] as u8.
    pub accel_state: [u8; MAX_CHANNELS],
    /// Per gyro channel, [`FaultReason`] as u8 (`None` for channels that are Ok).
    pub gyro_reason: [u8; MAX_CHANNELS],
    /// Per accelerometer channel, [`FaultReason`] as u8 (`None` for channels that are Ok).
    pub accel_reason: [u8; MAX_CHANNELS],
    /// Gyro parity test statistic, dimensionless (0 when there is no parity space: fewer than
    /// four gyros in service).
    pub gyro_test_statistic: f32,
    /// Accelerometer parity test statistic, dimensionless (0 when there is no parity space).
    pub accel_test_statistic: f32,
}

/// Bits of [`FusedImu::flags`].
pub mod fused_flags {
    /// The parity test declares a gyro fault but cannot blame a single channel: the candidates
    /// are Suspect and still fused.
    pub const GYRO_FAULT_DETECTED_NOT_ISOLATED: u32 = 1 << 0;
    /// As [`GYRO_FAULT_DETECTED_NOT_ISOLATED`], for the accelerometers.
    pub const ACCEL_FAULT_DETECTED_NOT_ISOLATED: u32 = 1 << 1;
    /// Fewer than three usable gyro channels: the rate is not valid.
    pub const GYRO_INSUFFICIENT: u32 = 1 << 2;
    /// Fewer than three usable accelerometer channels: the specific force is not valid.
    pub const ACCEL_INSUFFICIENT: u32 = 1 << 3;
    /// Fusion is still measuring the per-channel gyro biases at rest: the rate is not yet
    /// bias-corrected, so a navigator must not start its own static alignment on it.
    pub const GYRO_REST_BIAS_PENDING: u32 = 1 << 4;
    /// Fewer than three channels of the type are off the converter rails: the whole block reads
    /// full scale. The true value lies beyond the range, so the solution is not valid (a block
    /// fault or an over-range, never motion to integrate).
    pub const GYRO_SATURATED: u32 = 1 << 5;
    /// As [`GYRO_SATURATED`], for the accelerometers.
    pub const ACCEL_SATURATED: u32 = 1 << 6;
    /// The raw frame did not match the configured sensor block (payload version or channel
    /// counts): nothing was fused, the sample only carries the frame's header onwards so that
    /// downstream stages see the input and why it is unusable.
    pub const INPUT_REJECTED: u32 = 1 << 7;

    /// Every flag with its name, in bit order.
    pub const NAMES: [(u32, &str); 8] = [
        (GYRO_FAULT_DETECTED_NOT_ISOLATED, "gyro-fault-not-isolated"),
        (
            ACCEL_FAULT_DETECTED_NOT_ISOLATED,
            "accel-fault-not-isolated",
        ),
        (GYRO_INSUFFICIENT, "gyro-insufficient"),
        (ACCEL_INSUFFICIENT, "accel-insufficient"),
        (GYRO_REST_BIAS_PENDING, "gyro-rest-bias-pending"),
        (GYRO_SATURATED, "gyro-saturated"),
        (ACCEL_SATURATED, "accel-saturated"),
        (INPUT_REJECTED, "input-rejected"),
    ];
}

impl Default for FusedImu {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            n_gyro: 0,
            n_accel: 0,
            flags: 0,
            header: Header::default(),
            rate_rps: [0.0; 3],
            specific_force_mps2: [0.0; 3],
            rate_var: [0.0; 3],
            specific_force_var: [0.0; 3],
            gyro_state: [ChannelState::Absent as u8; MAX_CHANNELS],
            accel_state: [ChannelState::Absent as u8; MAX_CHANNELS],
            gyro_reason: [FaultReason::None as u8; MAX_CHANNELS],
            accel_reason: [FaultReason::None as u8; MAX_CHANNELS],
            gyro_test_statistic: 0.0,
            accel_test_statistic: 0.0,
        }
    }
}
