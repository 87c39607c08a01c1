//! Commands from the link: a COMMAND_LONG that asks fusion to re-admit an excluded channel, mapped
//! onto the fusion control topic, and its COMMAND_ACK. Off unless the configuration accepts
//! commands: a stream that only informs cannot be used to change the solution.
//!
//! The command is `MAV_CMD_USER_1` (31010, left to each system by the MAVLink common set) with
//! `param1` = 0 for a gyro, 1 for an accelerometer and `param2` = the channel index; rins answers
//! `MAV_RESULT_IN_PROGRESS` at once, then `ACCEPTED` once the channel passed its probation
//! against the other channels (or was not excluded), `FAILED` when the fault is still present or fusion
//! did not answer, `DENIED` for a channel the block does not have or when commands are not
//! accepted, `TEMPORARILY_REJECTED` when fusion is busy with other re-admissions.

use ipc_types::{FusionControl, FusionReply, PAYLOAD_VERSION, ReadmitOutcome, SensorType};

use crate::dialect::{COMMAND_ACK_DATA, COMMAND_LONG_DATA, MavCmd, MavResult};

/// The command rins takes for a re-admission.
pub const READMIT_COMMAND: MavCmd = MavCmd::MAV_CMD_USER_1;

/// What to do with a COMMAND_LONG.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Decision {
    /// Addressed to another system or component: not ours to answer.
    Ignore,
    /// Answer at once with this result.
    Answer(MavResult),
    /// Send this request to fusion; answer in progress now, the result when fusion replies.
    Readmit(FusionControl),
}

/// Whether `cmd`, from a peer, is rins's to carry out: `own` is rins's (system, component).
pub fn decide(
    cmd: &COMMAND_LONG_DATA,
    own: (u8, u8),
    accept_commands: bool,
    request_id: u32,
) -> Decision {
    let for_us =
        cmd.target_system == own.0 && (cmd.target_component == own.1 || cmd.target_component == 0);
    if !for_us {
        return Decision::Ignore;
    }
    if cmd.command != READMIT_COMMAND {
        return Decision::Answer(MavResult::MAV_RESULT_UNSUPPORTED);
    }
    if !accept_commands {
        return Decision::Answer(MavResult::MAV_RESULT_DENIED);
    }
    let sensor = match cmd.param1 {
        0.0 => SensorType::Gyro,
        1.0 => SensorType::Accel,
        _ => return Decision::Answer(MavResult::MAV_RESULT_DENIED),
    };
    let index = cmd.param2;
    if !(index.is_finite() && index >= 0.0 && index <= f32::from(u8::MAX) && index.fract() == 0.0) {
        return Decision::Answer(MavResult::MAV_RESULT_DENIED);
    }
    Decision::Readmit(FusionControl {
        version: PAYLOAD_VERSION,
        sensor: sensor as u8,
        channel: index as u8,
        request_id,
    })
}

/// The result of fusion's reply.
pub fn result_of(reply: &FusionReply) -> MavResult {
    match ReadmitOutcome::from_u8(reply.outcome) {
        Some(ReadmitOutcome::Readmitted | ReadmitOutcome::NotExcluded) => {
            MavResult::MAV_RESULT_ACCEPTED
        }
        Some(ReadmitOutcome::FaultStillPresent) => MavResult::MAV_RESULT_FAILED,
        Some(ReadmitOutcome::Busy) => MavResult::MAV_RESULT_TEMPORARILY_REJECTED,
        Some(ReadmitOutcome::NoSuchChannel | ReadmitOutcome::BadRequest) | None => {
            MavResult::MAV_RESULT_DENIED
        }
    }
}

/// The COMMAND_ACK of `command` with `result`, to the peer `(system, component)`.
pub fn ack(command: MavCmd, result: MavResult, peer: (u8, u8)) -> COMMAND_ACK_DATA {
    COMMAND_ACK_DATA {
        command,
        result,
        target_system: peer.0,
        target_component: peer.1,
        ..COMMAND_ACK_DATA::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn readmit(p1: f32, p2: f32) -> COMMAND_LONG_DATA {
        COMMAND_LONG_DATA {
            target_system: 1,
            target_component: 197,
            command: READMIT_COMMAND,
            param1: p1,
            param2: p2,
            ..COMMAND_LONG_DATA::default()
        }
    }

    #[test]
    fn maps_a_readmission_onto_fusion_control() {
        let Decision::Readmit(c) = decide(&readmit(1.0, 3.0), (1, 197), true, 77) else {
            panic!("not a readmission");
        };
        assert_eq!(
            (c.sensor, c.channel, c.request_id),
            (SensorType::Accel as u8, 3, 77)
        );
        // The whole system (component 0) counts as addressed.
        let to_system = COMMAND_LONG_DATA {
            target_component: 0,
            ..readmit(0.0, 1.0)
        };
        assert!(matches!(
            decide(&to_system, (1, 197), true, 1),
            Decision::Readmit(_)
        ));
    }

    #[test]
    fn refuses_what_it_must_not_do() {
        let own = (1, 197);
        assert_eq!(
            decide(&readmit(0.0, 1.0), (2, 197), true, 1),
            Decision::Ignore
        );
        assert_eq!(
            decide(&readmit(0.0, 1.0), (1, 191), true, 1),
            Decision::Ignore
        );
        let denied = Decision::Answer(MavResult::MAV_RESULT_DENIED);
        assert_eq!(decide(&readmit(0.0, 1.0), own, false, 1), denied);
        assert_eq!(decide(&readmit(2.0, 1.0), own, true, 1), denied);
        assert_eq!(decide(&readmit(0.0, 1.5), own, true, 1), denied);
        assert_eq!(decide(&readmit(0.0, -1.0), own, true, 1), denied);
        assert_eq!(decide(&readmit(0.0, f32::NAN), own, true, 1), denied);
        let other = COMMAND_LONG_DATA {
            command: MavCmd::MAV_CMD_COMPONENT_ARM_DISARM,
            ..readmit(0.0, 1.0)
        };
        assert_eq!(
            decide(&other, own, true, 1),
            Decision::Answer(MavResult::MAV_RESULT_UNSUPPORTED)
        );
    }

    #[test]
    fn fusion_outcomes_become_results() {
        let reply = |o: ReadmitOutcome| FusionReply {
            outcome: o as u8,
            ..FusionReply::default()
        };
        assert_eq!(
            result_of(&reply(ReadmitOutcome::Readmitted)),
            MavResult::MAV_RESULT_ACCEPTED
        );
        assert_eq!(
            result_of(&reply(ReadmitOutcome::FaultStillPresent)),
            MavResult::MAV_RESULT_FAILED
        );
        assert_eq!(
            result_of(&reply(ReadmitOutcome::Busy)),
            MavResult::MAV_RESULT_TEMPORARILY_REJECTED
        );
        let unknown = FusionReply {
            outcome: 200,
            ..FusionReply::default()
        };
        assert_eq!(result_of(&unknown), MavResult::MAV_RESULT_DENIED);
    }
}
