//! The fused result of one IMU frame: body rate and specific force with their variances, the
//! channels that entered each solution, and the fault-detection status that goes on the wire.

use crate::fdi::{ChannelEvents, SensorStatus};
use ipc_types::{FusedImu, fused_flags};

/// Fused body rate and specific force of one IMU frame, with the fault-detection status.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fused {
    /// Body rate, FRD, rad/s (zeros when `!gyro_ok`).
    pub rate: [f64; 3],
    /// Specific force, FRD, m/s² (zeros when `!accel_ok`).
    pub specific_force: [f64; 3],
    /// Variance of each rate axis, (rad/s)².
    pub rate_var: [f64; 3],
    /// Variance of each specific-force axis, (m/s²)².
    pub specific_force_var: [f64; 3],
    /// At least three active, well-conditioned gyro channels.
    pub gyro_ok: bool,
    /// At least three active, well-conditioned accelerometer channels.
    pub accel_ok: bool,
    /// Gyro channels that entered the solution (bit i = channel i).
    pub gyro_mask: u32,
    /// Accelerometer channels that entered the solution (bit i = channel i).
    pub accel_mask: u32,
    /// Per-channel states, reasons and parity statistic of the gyros.
    pub gyro_status: SensorStatus,
    /// Per-channel states, reasons and parity statistic of the accelerometers.
    pub accel_status: SensorStatus,
    /// Channel state changes of this frame (for the log).
    pub events: ChannelEvents,
    /// The vehicle is judged stationary (stationary reference usable).
    pub stationary: bool,
    /// The per-channel gyro rest bias is still being measured (see [`crate::rest_bias`]).
    pub rest_bias_pending: bool,
}

impl Fused {
    /// [`FusedImu::flags`] bits: insufficient channels, a saturated block, detected-not-isolated
    /// faults, the rest bias still pending.
    pub fn flags(&self) -> u32 {
        let mut flags = 0;
        if !self.gyro_ok {
            flags |= fused_flags::GYRO_INSUFFICIENT;
        }
        if !self.accel_ok {
            flags |= fused_flags::ACCEL_INSUFFICIENT;
        }
        if self.gyro_status.detected_not_isolated {
            flags |= fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED;
        }
        if self.accel_status.detected_not_isolated {
            flags |= fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED;
        }
        if self.rest_bias_pending {
            flags |= fused_flags::GYRO_REST_BIAS_PENDING;
        }
        if self.gyro_status.block_saturated {
            flags |= fused_flags::GYRO_SATURATED;
        }
        if self.accel_status.block_saturated {
            flags |= fused_flags::ACCEL_SATURATED;
        }
        flags
    }

    /// Writes the fault-detection fields of `msg`: flags, per-channel states and reasons, test
    /// statistics. The estimate fields and the header are the caller's.
    pub fn write_fdi(&self, msg: &mut FusedImu) {
        msg.flags = self.flags();
        msg.gyro_state = self.gyro_status.states.map(|s| s as u8);
        msg.accel_state = self.accel_status.states.map(|s| s as u8);
        msg.gyro_reason = self.gyro_status.reasons.map(|r| r as u8);
        msg.accel_reason = self.accel_status.reasons.map(|r| r as u8);
        msg.gyro_test_statistic = self.gyro_status.test_statistic as f32;
        msg.accel_test_statistic = self.accel_status.test_statistic as f32;
    }
}
