//! `rins readmit CHANNEL`: ask fusion to return an excluded channel to service.

use std::time::Duration;

use anyhow::{Result, anyhow};
use ipc_types::{FusionControl, PAYLOAD_VERSION, names};
use rins_runtime::tool_node::ToolNode;
use rins_sim::fault_command::ChannelId;

use crate::commands::control;

/// How long to wait for a fusion process to appear.
const LISTENER_WAIT: Duration = Duration::from_secs(2);
/// Fusion sends no acknowledgement; the command stays available this long, which covers the
/// longest sleep of fusion's loop with a wide margin.
const DELIVERY_GRACE: Duration = Duration::from_millis(500);

pub fn run(channel: &str) -> Result<()> {
    let channel = ChannelId::parse(channel).map_err(|e| anyhow!("{e}"))?;
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("readmit")?;
    let (node, settings) = (tool.node(), tool.settings());
    let command = FusionControl {
        version: PAYLOAD_VERSION,
        sensor: channel.sensor as u8,
        channel: channel.index,
        request_id: std::process::id(),
    };
    let sent = control::send(
        node,
        settings,
        names::FUSION_CONTROL,
        "fusion process",
        command,
        LISTENER_WAIT,
    )?;
    std::thread::sleep(DELIVERY_GRACE);
    println!(
        "{channel}: re-admission sent to {} fusion process(es)",
        sent.receivers
    );
    Ok(())
}
