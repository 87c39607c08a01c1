//! The header every pipeline payload carries: where its data came from and when each stage
//! published it, so that latency is measurable end to end.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

wire_enum! {
    /// Pipeline stages that stamp their publish time into [`Header::stage_pub_ns`]; the
    /// discriminant is the index into that array.
    pub enum Stage: usize {
        /// Serial frames decoded into raw samples.
        Acquisition = 0 => "acquisition",
        /// Raw IMU channels fused into body rate and specific force.
        Fusion = 1 => "fusion",
        /// Barometric pressure turned into altitude.
        Altimeter = 2 => "altimeter",
        /// The navigation solution.
        Navigator = 3 => "navigator",
    }
}

/// Carried by every message: where the data came from and when each stage published it.
/// Times are CLOCK_MONOTONIC nanoseconds; 0 means "stage not passed".
///
/// Acquisition writes the origin fields from the serial frame; each stage copies the header of its
/// input into its output and stamps its own publish time.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
pub struct Header {
    /// Sequence number of the originating serial frame, extended to 64 bits by acquisition.
    pub origin_seq: u64,
    /// Device time of the originating frame in microseconds, extended to 64 bits.
    pub origin_device_time_us: u64,
    /// When acquisition had the whole originating frame (CLOCK_MONOTONIC ns).
    pub origin_rx_ns: u64,
    /// Publish time of each stage passed, indexed by [`Stage`].
    pub stage_pub_ns: [u64; Stage::COUNT],
}

impl Header {
    /// Records that `stage` published this message at `now_ns` (CLOCK_MONOTONIC ns).
    pub fn stamp(&mut self, stage: Stage, now_ns: u64) {
        self.stage_pub_ns[stage as usize] = now_ns;
    }

    /// When `stage` published this message (CLOCK_MONOTONIC ns), 0 if it did not pass it.
    pub fn stage_ns(&self, stage: Stage) -> u64 {
        self.stage_pub_ns[stage as usize]
    }
}
