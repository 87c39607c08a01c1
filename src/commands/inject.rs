//! `rins inject CHANNEL FAULT [ARG]`: apply a fault to one channel of the running simulator (or
//! `rins inject disconnect --duration S`: unplug its serial device; or `rins inject gnss FAULT
//! [ARG]`: a fault of its GNSS receiver) and wait for the simulator to confirm the device time it
//! took effect.

use std::time::{Duration, Instant};

use anyhow::{Result, anyhow, bail};
use ipc_types::{FaultApplied, FaultOutcome, SimControl, names};
use rins_runtime::ipc::TopicSubscriber;
use rins_runtime::tool_node::ToolNode;
use rins_sim::sim_command::SimCommand;

use crate::cli::InjectArgs;
use crate::commands::control;

/// How long to wait for a simulator to appear (e.g. while `rins up` is starting).
const LISTENER_WAIT: Duration = Duration::from_secs(2);
/// How long the simulator may take to confirm; it handles commands every IMU tick.
const CONFIRM_WAIT: Duration = Duration::from_secs(2);

/// Whether `event` answers `sent` (same channel, fault and parameter).
fn answers(event: &FaultApplied, sent: &SimControl) -> bool {
    event.sensor == sent.sensor
        && event.channel == sent.channel
        && event.fault == sent.fault
        && event.param.to_bits() == sent.param.to_bits()
}

pub fn run(args: &InjectArgs) -> Result<()> {
    let command = SimCommand::parse_inject(
        &args.channel,
        args.fault.as_deref(),
        args.arg.as_deref(),
        args.duration.as_deref(),
    )
    .map_err(|e| anyhow!("{e}"))?;
    // Ports are made after the tool node, so they are dropped before it cleans up.
    let tool = ToolNode::join("inject")?;
    let (node, settings) = (tool.node(), tool.settings());
    // Subscribe to the confirmations before sending, so the answer cannot be missed.
    let confirmations = TopicSubscriber::<FaultApplied>::new(node, names::SIM_FAULT_APPLIED)?;
    let control = command.to_control();
    let _sent = control::send(
        node,
        settings,
        names::SIM_CONTROL,
        "simulator",
        control,
        LISTENER_WAIT,
    )?;
    let deadline = Instant::now() + CONFIRM_WAIT;
    loop {
        while let Some(event) = confirmations.receive()? {
            if !answers(&event, &control) {
                continue;
            }
            return match FaultOutcome::from_u8(event.outcome) {
                Some(FaultOutcome::Applied) => {
                    println!(
                        "{command}: applied at device time {:.6} s",
                        event.device_time_us as f64 * 1e-6
                    );
                    Ok(())
                }
                Some(FaultOutcome::NoSuchChannel)
                    if control.sensor == SimControl::GNSS_RECEIVER =>
                {
                    bail!(
                        "gnss: the simulator has no GNSS receiver (run rins up --gnss, or rins sim --gnss-link)"
                    )
                }
                Some(FaultOutcome::NoSuchChannel) => bail!(
                    "channel {:?}: the simulated sensor block has no such channel",
                    command.target()
                ),
                Some(FaultOutcome::InvalidParameter) => {
                    bail!("{command}: the simulator rejected the parameter")
                }
                _ => bail!(
                    "{command}: the simulator did not understand the command (different rins version?)"
                ),
            };
        }
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            bail!("{command}: sent, but the simulator did not confirm it within {CONFIRM_WAIT:?}");
        }
        confirmations.wait(left.min(Duration::from_millis(50)))?;
    }
}
