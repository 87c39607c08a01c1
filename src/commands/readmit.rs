//! `rins readmit CHANNEL [--timeout S]`: ask fusion to return an excluded channel to service and
//! wait for its answer. Fusion answers once the channel stayed in the solution through its
//! probation (`readmitted`), or when it is excluded again within it (`fault-still-present`, with
//! the test that found it), or at once when there is nothing to do or the request cannot be carried
//! out. Anything but `readmitted` or `not-excluded` is a failure (non-zero exit), and so is silence.

use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use ipc_types::{FaultReason, FusionControl, FusionReply, PAYLOAD_VERSION, ReadmitOutcome, names};
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::tool_node::ToolNode;
use rins_sim::fault_command::ChannelId;

use crate::commands::control;

/// How long to wait for a fusion process to appear.
const LISTENER_WAIT: Duration = Duration::from_secs(2);

/// The sentence for fusion's answer, and whether it is a success.
pub fn describe(channel: &ChannelId, reply: &FusionReply) -> (String, bool) {
    let reason = FaultReason::from_u8(reply.reason)
        .map_or_else(|| format!("reason {}", reply.reason), |r| r.name().into());
    match ReadmitOutcome::from_u8(reply.outcome) {
        Some(ReadmitOutcome::Readmitted) => (
            format!("{channel}: readmitted (passed its probation against the other channels)"),
            true,
        ),
        Some(ReadmitOutcome::NotExcluded) => (
            format!("{channel}: not excluded, nothing to do (it is in the solution)"),
            true,
        ),
        Some(ReadmitOutcome::FaultStillPresent) => (
            format!(
                "{channel}: refused: excluded again during its probation ({reason}), the fault is \
                 still present"
            ),
            false,
        ),
        Some(ReadmitOutcome::NoSuchChannel) => (
            format!("{channel}: refused: the sensor block has no such channel"),
            false,
        ),
        Some(ReadmitOutcome::BadRequest) => (
            format!(
                "{channel}: refused: fusion could not read the request (payload version {} here)",
                PAYLOAD_VERSION
            ),
            false,
        ),
        Some(ReadmitOutcome::Busy) => (
            format!("{channel}: refused: too many re-admissions on probation, ask again"),
            false,
        ),
        None => (
            format!(
                "{channel}: fusion answered with outcome {}, unknown to this build",
                reply.outcome
            ),
            false,
        ),
    }
}

pub fn run(channel: &str, timeout_s: f64) -> Result<()> {
    if !(timeout_s.is_finite() && timeout_s > 0.0) {
        bail!("--timeout {timeout_s}: must be a positive number of seconds");
    }
    let channel = ChannelId::parse(channel).map_err(|e| anyhow!("{e}"))?;
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("readmit")?;
    let (node, settings) = (tool.node(), tool.settings());
    // Subscribed before the request leaves, so the answer cannot pass by unseen.
    let replies = TopicSubscriber::<FusionReply>::new(node, names::FUSION_REPLY)?;
    let request_id = std::process::id();
    let command = FusionControl {
        version: PAYLOAD_VERSION,
        sensor: channel.sensor as u8,
        channel: channel.index,
        request_id,
    };
    let _sent = control::send(
        node,
        settings,
        names::FUSION_CONTROL,
        "fusion process",
        command,
        LISTENER_WAIT,
    )?;
    let deadline = Instant::now() + Duration::from_secs_f64(timeout_s);
    while Instant::now() < deadline {
        replies.wait(Duration::from_millis(50))?;
        while let Some(reply) = replies.receive()? {
            if reply.request_id != request_id
                || reply.sensor != command.sensor
                || reply.channel != command.channel
            {
                continue;
            }
            let (text, success) = describe(&channel, &reply);
            if success {
                println!("{text}");
                return Ok(());
            }
            bail!("{text}");
        }
    }
    bail!(
        "{channel}: no answer from fusion within {timeout_s} s (it answers once raw IMU frames \
         carry the channel through its probation: is the sensor block sending?)"
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::SensorType;

    #[test]
    fn only_readmitted_and_not_excluded_are_successes() {
        let channel = ChannelId {
            sensor: SensorType::Gyro,
            index: 2,
        };
        let reply = |outcome: ReadmitOutcome, reason: FaultReason| FusionReply {
            outcome: outcome as u8,
            reason: reason as u8,
            ..FusionReply::default()
        };
        let (text, ok) = describe(
            &channel,
            &reply(ReadmitOutcome::Readmitted, FaultReason::None),
        );
        assert!(ok && text.starts_with("gyro2: readmitted"), "{text}");
        assert!(
            describe(
                &channel,
                &reply(ReadmitOutcome::NotExcluded, FaultReason::None)
            )
            .1
        );
        let (text, ok) = describe(
            &channel,
            &reply(ReadmitOutcome::FaultStillPresent, FaultReason::Missing),
        );
        assert!(
            !ok && text.contains("(missing)") && text.contains("still present"),
            "{text}"
        );
        for refused in [
            ReadmitOutcome::NoSuchChannel,
            ReadmitOutcome::BadRequest,
            ReadmitOutcome::Busy,
        ] {
            let (text, ok) = describe(&channel, &reply(refused, FaultReason::None));
            assert!(!ok && text.contains("refused"), "{text}");
        }
        let unknown = FusionReply {
            outcome: 200,
            ..FusionReply::default()
        };
        assert!(!describe(&channel, &unknown).1);
    }
}
