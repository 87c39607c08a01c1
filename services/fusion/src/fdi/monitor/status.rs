//! The per-sample status of the monitor: each channel's state and reason from the latched
//! exclusions and this sample's suspects, with the test statistic and the flags.

use super::{MonitorInput, SensorMonitor};
use crate::fdi::report::SensorStatus;
use ipc_types::{ChannelState, FaultReason};

/// What the parity test of one sample concluded.
pub(super) struct ParityOutcome {
    /// The test statistic.
    pub t: f64,
    /// The parity dimension.
    pub dim: usize,
    /// Suspects of a detected-but-unisolated fault.
    pub candidates: u32,
    /// The learning phase is on (declarations suspended).
    pub learning: bool,
}

/// What the health checks and the recovery re-test decided on one sample, for the status.
pub(super) struct HealthOutcome {
    /// Channels Suspect for a genuine over-range.
    pub saturated_suspect: u32,
    /// Fewer than three channels in service are off the converter rails.
    pub block_saturated: bool,
    /// Channels the recovery re-test returned on this sample.
    pub auto_readmitted: u32,
    /// The noise-outlier check's margin on this sample (see [`SensorStatus::noise_peak`]).
    pub noise_peak: f64,
}

impl SensorMonitor {
    /// The status of this sample from the parity and health outcomes.
    pub(super) fn build_status(
        &self,
        parity: &ParityOutcome,
        health: &HealthOutcome,
        input: &MonitorInput,
    ) -> SensorStatus {
        let saturated_suspect = health.saturated_suspect;
        let n = self.geometry.n();
        let candidates = parity.candidates;
        let mut status = SensorStatus {
            n,
            test_statistic: parity.t,
            threshold: self.threshold,
            parity_dimension: parity.dim,
            detected_not_isolated: candidates != 0,
            device_error: input.device_error,
            learning: parity.learning,
            block_saturated: health.block_saturated,
            auto_readmitted: health.auto_readmitted,
            noise_peak: health.noise_peak,
            ..SensorStatus::ABSENT
        };
        for i in 0..n {
            let bit = 1u32 << i;
            let (state, reason) = if self.excluded[i] != FaultReason::None {
                (ChannelState::Excluded, self.excluded[i])
            } else {
                let reason = if candidates & bit != 0 {
                    FaultReason::Parity
                } else if saturated_suspect & bit != 0 {
                    FaultReason::Saturated
                } else if self.noisy_suspect & bit != 0 {
                    FaultReason::Noisy
                } else if input.temperature_suspect & bit != 0 {
                    FaultReason::Temperature
                } else if input.device_error {
                    FaultReason::DeviceError
                } else {
                    FaultReason::None
                };
                if reason == FaultReason::None {
                    (ChannelState::Ok, reason)
                } else {
                    (ChannelState::Suspect, reason)
                }
            };
            status.states[i] = state;
            status.reasons[i] = reason;
        }
        status
    }
}
