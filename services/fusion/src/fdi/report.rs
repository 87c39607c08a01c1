//! What fault detection reports per sample: channel states and reasons, the test statistic, the
//! detected-not-isolated flag, and the state changes of this sample — all fixed size.

use crate::geometry::MAX_CHANNELS;
use ipc_types::{ChannelState, FaultReason, SensorType};

/// Fault-detection status of one sensor type for one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SensorStatus {
    /// Channels fitted (N); entries at and above N are `Absent`.
    pub n: usize,
    /// State of each channel.
    pub states: [ChannelState; MAX_CHANNELS],
    /// Why a channel is Suspect or Excluded (`None` when Ok or Absent).
    pub reasons: [FaultReason; MAX_CHANNELS],
    /// Parity test statistic T (0 when there is no parity space).
    pub test_statistic: f64,
    /// Threshold T is compared with (infinite when there is no parity space).
    pub threshold: f64,
    /// Parity dimension of the active set (N_active − 3, 0 below 4 channels).
    pub parity_dimension: usize,
    /// A fault is declared but no single channel could be blamed; the candidates are Suspect and
    /// still fused.
    pub detected_not_isolated: bool,
    /// The device reports an error (block-level, names no channel).
    pub device_error: bool,
    /// The adaptive noise estimate is still learning: parity declarations are suspended.
    pub learning: bool,
    /// Fewer than three channels in service are off the converter rails: the block reads full
    /// scale, the solution is not valid.
    pub block_saturated: bool,
    /// Channels re-admitted by the recovery re-test on this sample (see [`super::recovery`]).
    pub auto_readmitted: u32,
    /// When a noise-outlier block ended on this sample: the largest channel noise over its bound
    /// (above 1 = an outlier); 0 otherwise. The margin of that check, as T / threshold is the
    /// parity test's.
    pub noise_peak: f64,
}

impl SensorStatus {
    /// All channels absent (no sensor of this type fitted).
    pub const ABSENT: Self = Self {
        n: 0,
        states: [ChannelState::Absent; MAX_CHANNELS],
        reasons: [FaultReason::None; MAX_CHANNELS],
        test_statistic: 0.0,
        threshold: f64::INFINITY,
        parity_dimension: 0,
        detected_not_isolated: false,
        device_error: false,
        learning: false,
        block_saturated: false,
        auto_readmitted: 0,
        noise_peak: 0.0,
    };

    /// Channels in state `state` (bit i = channel i).
    pub fn mask_of(&self, state: ChannelState) -> u32 {
        self.states
            .iter()
            .enumerate()
            .filter(|(_, s)| **s == state)
            .fold(0, |m, (i, _)| m | 1 << i)
    }
}

impl Default for SensorStatus {
    fn default() -> Self {
        Self::ABSENT
    }
}

/// A change of one channel's state or reason.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ChannelEvent {
    /// Gyro or accelerometer.
    pub sensor: SensorType,
    /// 0-based channel index within its type.
    pub channel: u8,
    /// State before the change.
    pub old_state: ChannelState,
    /// State after the change.
    pub new_state: ChannelState,
    /// Reason before the change.
    pub old_reason: FaultReason,
    /// Reason of the new state (`None` when the channel became Ok).
    pub reason: FaultReason,
}

/// Most events one sample can carry: every channel of both types changing once.
pub const MAX_EVENTS: usize = 2 * MAX_CHANNELS;

/// The state changes of one sample, in channel order (gyro first).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelEvents {
    len: usize,
    events: [ChannelEvent; MAX_EVENTS],
}

const NO_EVENT: ChannelEvent = ChannelEvent {
    sensor: SensorType::Gyro,
    channel: 0,
    old_state: ChannelState::Ok,
    new_state: ChannelState::Ok,
    old_reason: FaultReason::None,
    reason: FaultReason::None,
};

impl ChannelEvents {
    /// No events.
    pub const EMPTY: Self = Self {
        len: 0,
        events: [NO_EVENT; MAX_EVENTS],
    };

    /// The events of this sample.
    pub fn as_slice(&self) -> &[ChannelEvent] {
        &self.events[..self.len]
    }

    /// Number of events this sample.
    pub fn len(&self) -> usize {
        self.len
    }

    /// Whether no channel changed this sample.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Appends an event; each channel changes at most once per sample, so this cannot overflow
    /// (a surplus event would be dropped rather than panic).
    pub(crate) fn push(&mut self, event: ChannelEvent) {
        if let Some(slot) = self.events.get_mut(self.len) {
            *slot = event;
            self.len += 1;
        }
    }

    /// Appends the differences between two statuses of `sensor`.
    pub(crate) fn record(&mut self, sensor: SensorType, old: &SensorStatus, new: &SensorStatus) {
        for i in 0..MAX_CHANNELS {
            if old.states[i] != new.states[i] || old.reasons[i] != new.reasons[i] {
                self.push(ChannelEvent {
                    sensor,
                    channel: i as u8,
                    old_state: old.states[i],
                    new_state: new.states[i],
                    old_reason: old.reasons[i],
                    reason: new.reasons[i],
                });
            }
        }
    }
}

impl Default for ChannelEvents {
    fn default() -> Self {
        Self::EMPTY
    }
}
