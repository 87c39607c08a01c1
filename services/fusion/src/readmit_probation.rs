//! The answer to a re-admission request. Answering "accepted" at once would tell the operator the
//! opposite of what happened when the fault is still there, so the answer waits for the verdict.
//!
//! A re-admitted channel is normally tested by its monitor while it stays out of the solution (see
//! [`crate::fdi::probation`]): while the monitor says it is on probation the request waits; when
//! the test ends, the channel is either back in the solution (`readmitted`) or still excluded,
//! now with the reason of the test it failed (`fault-still-present` with that reason). A channel
//! the monitor returned at once (the others had no solution to test it against) is watched for a
//! configured number of fused samples instead: excluded again within them, `fault-still-present`;
//! in service throughout, `readmitted`. Requests that cannot be carried out are answered at once.
//!
//! Pure bookkeeping on fixed arrays: the per-sample check costs one comparison while nothing is on
//! probation and never allocates.

use ipc_types::{
    ChannelState, FaultReason, FusedImu, FusionControl, FusionReply, PAYLOAD_VERSION,
    ReadmitOutcome, SensorType,
};

/// Re-admissions that can be on probation at once; a further one is answered `busy`.
pub const MAX_ON_PROBATION: usize = 8;

/// Answers waiting to be published; more in one batch are unlikely (one per request).
pub const MAX_REPLIES: usize = 2 * MAX_ON_PROBATION;

/// What the fuser said to a re-admission (the fuser's own result, without its error type).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReadmitResult {
    /// The channel was excluded and is back in the solution.
    Readmitted,
    /// The channel was not excluded.
    NotExcluded,
    /// The sensor block has no such channel.
    NoSuchChannel,
}

#[derive(Debug, Clone, Copy)]
struct OnProbation {
    request: FusionControl,
    sensor: SensorType,
    remaining: u32,
    /// The monitor tested the channel out of the solution on an earlier sample.
    tested: bool,
}

/// Re-admissions on probation and answers not yet published.
#[derive(Debug, Clone)]
pub struct ReadmitProbation {
    samples: u32,
    pid: u32,
    pending: [Option<OnProbation>; MAX_ON_PROBATION],
    on_probation: usize,
    replies: [FusionReply; MAX_REPLIES],
    n_replies: usize,
}

impl ReadmitProbation {
    /// Probation of `samples` fused samples; answers carry `pid`.
    pub fn new(samples: u32, pid: u32) -> Self {
        Self {
            samples,
            pid,
            pending: [None; MAX_ON_PROBATION],
            on_probation: 0,
            replies: [FusionReply::default(); MAX_REPLIES],
            n_replies: 0,
        }
    }

    /// Handles one request: `readmit` carries it out on the fuser (called only for a request
    /// that can be read).
    pub fn on_request(
        &mut self,
        request: &FusionControl,
        readmit: impl FnOnce(SensorType, usize) -> ReadmitResult,
    ) {
        let sensor = SensorType::from_u8(request.sensor);
        let Some(sensor) = sensor.filter(|_| request.version == PAYLOAD_VERSION) else {
            self.answer(request, ReadmitOutcome::BadRequest, FaultReason::None);
            return;
        };
        let Some(slot) = self.pending.iter_mut().find(|p| p.is_none()) else {
            self.answer(request, ReadmitOutcome::Busy, FaultReason::None);
            return;
        };
        match readmit(sensor, usize::from(request.channel)) {
            ReadmitResult::Readmitted => {
                *slot = Some(OnProbation {
                    request: *request,
                    sensor,
                    remaining: self.samples,
                    tested: false,
                });
                self.on_probation += 1;
            }
            ReadmitResult::NotExcluded => {
                self.answer(request, ReadmitOutcome::NotExcluded, FaultReason::None)
            }
            ReadmitResult::NoSuchChannel => {
                self.answer(request, ReadmitOutcome::NoSuchChannel, FaultReason::None)
            }
        }
    }

    /// Follows every channel on probation through one fused sample. `testing(sensor, channel)`:
    /// the monitor still tests the channel out of the solution (no verdict yet).
    pub fn on_fused(&mut self, fused: &FusedImu, testing: impl Fn(SensorType, usize) -> bool) {
        if self.on_probation == 0 {
            return;
        }
        for i in 0..MAX_ON_PROBATION {
            let Some(mut p) = self.pending[i] else {
                continue;
            };
            let (states, reasons) = match p.sensor {
                SensorType::Gyro => (&fused.gyro_state, &fused.gyro_reason),
                SensorType::Accel => (&fused.accel_state, &fused.accel_reason),
            };
            let channel = usize::from(p.request.channel);
            if testing(p.sensor, channel) {
                p.tested = true;
                self.pending[i] = Some(p);
                continue;
            }
            let excluded = states.get(channel).copied() == Some(ChannelState::Excluded as u8);
            p.remaining = p.remaining.saturating_sub(1);
            let outcome = if excluded {
                let reason = reasons
                    .get(channel)
                    .and_then(|r| FaultReason::from_u8(*r))
                    .unwrap_or(FaultReason::None);
                Some((ReadmitOutcome::FaultStillPresent, reason))
            } else if p.tested || p.remaining == 0 {
                // Passed the monitor's tests and back in the solution, or in service throughout.
                Some((ReadmitOutcome::Readmitted, FaultReason::None))
            } else {
                None
            };
            match outcome {
                Some((outcome, reason)) => {
                    self.answer(&p.request, outcome, reason);
                    self.pending[i] = None;
                    self.on_probation -= 1;
                }
                None => self.pending[i] = Some(p),
            }
        }
    }

    /// Hands every answer waiting to `publish`, oldest first, and forgets them.
    pub fn take_replies(&mut self, mut publish: impl FnMut(FusionReply)) {
        for reply in &self.replies[..self.n_replies] {
            publish(*reply);
        }
        self.n_replies = 0;
    }

    /// Re-admissions on probation now.
    pub fn on_probation(&self) -> usize {
        self.on_probation
    }

    fn answer(&mut self, request: &FusionControl, outcome: ReadmitOutcome, reason: FaultReason) {
        let reply = FusionReply {
            version: PAYLOAD_VERSION,
            sensor: request.sensor,
            channel: request.channel,
            request_id: request.request_id,
            outcome: outcome as u8,
            reason: reason as u8,
            _pad: [0; 2],
            pid: self.pid,
        };
        // Room for every pending answer: at most one per request on probation plus the requests
        // of one batch; beyond that the oldest answer is the one a waiting sender has given up on.
        if self.n_replies == MAX_REPLIES {
            self.replies.copy_within(1.., 0);
            self.n_replies -= 1;
        }
        self.replies[self.n_replies] = reply;
        self.n_replies += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(sensor: SensorType, channel: u8, id: u32) -> FusionControl {
        FusionControl {
            version: PAYLOAD_VERSION,
            sensor: sensor as u8,
            channel,
            request_id: id,
        }
    }

    fn fused_with(state: ChannelState, reason: FaultReason) -> FusedImu {
        let mut f = FusedImu::default();
        f.gyro_state[..4].fill(ChannelState::Ok as u8);
        f.gyro_state[2] = state as u8;
        f.gyro_reason[2] = reason as u8;
        f
    }

    /// A monitor that returned the channel at once.
    fn not_testing(_: SensorType, _: usize) -> bool {
        false
    }

    fn replies(p: &mut ReadmitProbation) -> Vec<FusionReply> {
        let mut out = Vec::new();
        p.take_replies(|r| out.push(r));
        out
    }

    #[test]
    fn a_channel_that_stays_clean_is_readmitted_after_the_probation() {
        let mut p = ReadmitProbation::new(3, 77);
        p.on_request(&request(SensorType::Gyro, 2, 9), |_, _| {
            ReadmitResult::Readmitted
        });
        let ok = fused_with(ChannelState::Ok, FaultReason::None);
        p.on_fused(&ok, not_testing);
        p.on_fused(&ok, not_testing);
        assert!(
            replies(&mut p).is_empty(),
            "answered before the probation ended"
        );
        p.on_fused(&ok, not_testing);
        let r = replies(&mut p);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].outcome, ReadmitOutcome::Readmitted as u8);
        assert_eq!((r[0].request_id, r[0].channel, r[0].pid), (9, 2, 77));
        assert_eq!(p.on_probation(), 0);
        assert!(replies(&mut p).is_empty(), "an answer is given once");
    }

    #[test]
    fn a_channel_excluded_again_is_a_fault_still_present_with_its_reason() {
        let mut p = ReadmitProbation::new(1000, 1);
        p.on_request(&request(SensorType::Gyro, 2, 5), |_, _| {
            ReadmitResult::Readmitted
        });
        p.on_fused(
            &fused_with(ChannelState::Ok, FaultReason::None),
            not_testing,
        );
        // A suspect channel is still in the solution: no verdict yet.
        p.on_fused(
            &fused_with(ChannelState::Suspect, FaultReason::Parity),
            not_testing,
        );
        assert!(replies(&mut p).is_empty());
        p.on_fused(
            &fused_with(ChannelState::Excluded, FaultReason::Missing),
            not_testing,
        );
        let r = replies(&mut p);
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].outcome, ReadmitOutcome::FaultStillPresent as u8);
        assert_eq!(r[0].reason, FaultReason::Missing as u8);
    }

    #[test]
    fn a_channel_tested_out_of_the_solution_is_answered_when_the_test_ends() {
        let testing = std::cell::Cell::new(true);
        let monitor = |sensor: SensorType, channel: usize| {
            sensor == SensorType::Gyro && channel == 2 && testing.get()
        };
        let mut p = ReadmitProbation::new(1000, 1);
        p.on_request(&request(SensorType::Gyro, 2, 5), |_, _| {
            ReadmitResult::Readmitted
        });
        p.on_request(&request(SensorType::Gyro, 2, 6), |_, _| {
            ReadmitResult::Readmitted
        });
        // Out of the solution while tested: Excluded with its old reason, no verdict yet.
        let under_test = fused_with(ChannelState::Excluded, FaultReason::StationaryReference);
        for _ in 0..2000 {
            p.on_fused(&under_test, monitor);
        }
        assert!(replies(&mut p).is_empty(), "answered while still tested");
        // Failed its bias test: still excluded, now for parity.
        testing.set(false);
        p.on_fused(
            &fused_with(ChannelState::Excluded, FaultReason::Parity),
            monitor,
        );
        let r = replies(&mut p);
        assert_eq!(r.len(), 2);
        assert!(
            r.iter()
                .all(|r| r.outcome == ReadmitOutcome::FaultStillPresent as u8
                    && r.reason == FaultReason::Parity as u8)
        );
        // Passed: back in the solution, answered on that sample, long before 1000 samples.
        testing.set(true);
        p.on_request(&request(SensorType::Gyro, 2, 7), |_, _| {
            ReadmitResult::Readmitted
        });
        p.on_fused(&under_test, monitor);
        testing.set(false);
        p.on_fused(&fused_with(ChannelState::Ok, FaultReason::None), monitor);
        let r = replies(&mut p);
        assert_eq!(r.len(), 1);
        assert_eq!(
            (r[0].request_id, r[0].outcome),
            (7, ReadmitOutcome::Readmitted as u8)
        );
        assert_eq!(p.on_probation(), 0);
    }

    #[test]
    fn the_other_sensor_type_does_not_count() {
        let mut p = ReadmitProbation::new(2, 1);
        p.on_request(&request(SensorType::Accel, 2, 5), |_, _| {
            ReadmitResult::Readmitted
        });
        // Gyro 2 excluded says nothing about accelerometer 2.
        let gyro_out = fused_with(ChannelState::Excluded, FaultReason::Parity);
        p.on_fused(&gyro_out, not_testing);
        p.on_fused(&gyro_out, not_testing);
        let r = replies(&mut p);
        assert_eq!(r[0].outcome, ReadmitOutcome::Readmitted as u8);
    }

    #[test]
    fn requests_that_cannot_be_carried_out_are_answered_at_once() {
        let mut p = ReadmitProbation::new(10, 1);
        p.on_request(&request(SensorType::Gyro, 9, 1), |_, _| {
            ReadmitResult::NoSuchChannel
        });
        p.on_request(&request(SensorType::Gyro, 1, 2), |_, _| {
            ReadmitResult::NotExcluded
        });
        let unknown_sensor = FusionControl {
            sensor: 7,
            ..request(SensorType::Gyro, 0, 3)
        };
        let mut called = false;
        p.on_request(&unknown_sensor, |_, _| {
            called = true;
            ReadmitResult::Readmitted
        });
        let old_version = FusionControl {
            version: PAYLOAD_VERSION - 1,
            ..request(SensorType::Gyro, 0, 4)
        };
        p.on_request(&old_version, |_, _| {
            called = true;
            ReadmitResult::Readmitted
        });
        assert!(!called, "a request that cannot be read reached the fuser");
        let outcomes: Vec<(u32, u8)> = replies(&mut p)
            .iter()
            .map(|r| (r.request_id, r.outcome))
            .collect();
        assert_eq!(
            outcomes,
            [
                (1, ReadmitOutcome::NoSuchChannel as u8),
                (2, ReadmitOutcome::NotExcluded as u8),
                (3, ReadmitOutcome::BadRequest as u8),
                (4, ReadmitOutcome::BadRequest as u8),
            ]
        );
        assert_eq!(p.on_probation(), 0);
    }

    #[test]
    fn beyond_the_capacity_a_request_is_answered_busy_without_readmitting() {
        let mut p = ReadmitProbation::new(10, 1);
        for id in 0..MAX_ON_PROBATION as u32 {
            p.on_request(&request(SensorType::Gyro, 0, id), |_, _| {
                ReadmitResult::Readmitted
            });
        }
        let mut called = false;
        p.on_request(&request(SensorType::Gyro, 0, 99), |_, _| {
            called = true;
            ReadmitResult::Readmitted
        });
        assert!(!called);
        let r = replies(&mut p);
        assert_eq!(
            (r[0].request_id, r[0].outcome),
            (99, ReadmitOutcome::Busy as u8)
        );
    }
}
