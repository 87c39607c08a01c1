//! The simulated device's side of the simulator process: its serial lines (the sensor block's and
//! the GNSS receiver's), the outage of an unplugged line, and the commands applied to the device
//! between two samples, each described for [`ipc_types::names::SIM_FAULT_APPLIED`].

use std::io::Write;

use ipc_types::{FaultApplied, FaultOutcome, PAYLOAD_VERSION, SimControl, SimFault};

use crate::device_fault::Disconnect;
use crate::fault_command::{ControlError, FaultCommand, WhiteNoise};
use crate::gnss_receiver::GnssReceiver;
use crate::outage::Outage;
use crate::serial_line::SerialLine;
use crate::sim_command::SimCommand;
use crate::simulator::{Simulator, TruthSample};

/// When a new pseudo-terminal cannot be made, the next try comes this much device time later.
const PLUG_RETRY_S: f64 = 0.1;

/// The simulated GNSS receiver and its line.
pub(crate) struct GnssDevice {
    receiver: GnssReceiver,
    line: SerialLine,
    /// Bytes of the tick, reused.
    buf: Vec<u8>,
}

impl GnssDevice {
    /// `receiver` sending on `line`.
    pub(crate) fn new(receiver: GnssReceiver, line: SerialLine) -> Self {
        Self {
            receiver,
            line,
            buf: Vec::with_capacity(1024),
        }
    }

    /// Applies a receiver fault before the next step.
    fn apply(&mut self, sim: &Simulator, fault: SimFault, param: f64) -> FaultOutcome {
        match self.receiver.apply(fault, param, next_sample_time_us(sim)) {
            Ok(()) => {
                tracing::info!(
                    fault = fault.name(),
                    param,
                    time_s = sim.time_s(),
                    "GNSS receiver fault applied"
                );
                FaultOutcome::Applied
            }
            Err(why) => {
                tracing::warn!(
                    fault = fault.name(),
                    param,
                    "GNSS receiver fault ignored: {why}"
                );
                FaultOutcome::InvalidParameter
            }
        }
    }

    /// The receiver's share of one tick: its bytes, if any, on its line.
    pub(crate) fn tick(&mut self, truth: &TruthSample) {
        self.buf.clear();
        self.receiver.tick(truth, &mut self.buf);
        if !self.buf.is_empty() {
            // Nobody reading (the gnss service restarting): the epoch is lost, as on a real line.
            let _ = self.line.send(&self.buf);
        }
    }
}

/// Device time of the sample the next step produces, µs (as [`Simulator::step`] stamps it).
fn next_sample_time_us(sim: &Simulator) -> u64 {
    (sim.tick() as f64 * sim.imu_period_s() * 1e6).round() as u64
}

/// Applies one channel fault before the next step, so it affects that step's sample, and
/// describes what happened for [`ipc_types::names::SIM_FAULT_APPLIED`].
pub(crate) fn apply_fault(
    sim: &mut Simulator,
    command: &FaultCommand,
    noise: &WhiteNoise,
) -> FaultApplied {
    let channel = usize::from(command.channel.index);
    let sensor = command.channel.inertial_sensor();
    let result = match command.channel_fault(noise) {
        Some(fault) => sim.inject_fault(sensor, channel, fault),
        None => sim.clear_fault(sensor, channel),
    };
    let outcome = match result {
        Ok(()) => {
            tracing::info!(fault = %command, time_s = sim.time_s(), "fault applied");
            FaultOutcome::Applied
        }
        Err(crate::SimError::NoSuchChannel { .. }) => {
            tracing::warn!(fault = %command, "fault ignored: the sensor block has no such channel");
            FaultOutcome::NoSuchChannel
        }
        Err(e) => {
            tracing::warn!(fault = %command, error = %e, "fault ignored");
            FaultOutcome::InvalidParameter
        }
    };
    FaultApplied {
        outcome: outcome as u8,
        device_time_us: next_sample_time_us(sim),
        ..fault_event(&command.to_control())
    }
}

/// The event for a command as received, before its outcome is known.
fn fault_event(control: &SimControl) -> FaultApplied {
    FaultApplied {
        version: PAYLOAD_VERSION,
        sensor: control.sensor,
        channel: control.channel,
        fault: control.fault,
        outcome: FaultOutcome::UnknownCommand as u8,
        _pad: [0; 2],
        device_time_us: 0,
        param: control.param,
    }
}

/// The device's side of the simulation: its serial line and when an unplugged line comes back.
pub(crate) struct Device {
    /// The sensor block's line.
    pub(crate) line: SerialLine,
    outage: Outage,
    imu_rate_hz: f64,
    /// The GNSS receiver, when one is fitted.
    pub(crate) gnss: Option<GnssDevice>,
}

impl Device {
    /// The sensor block on `line`, sampled at `imu_rate_hz`, with the receiver `gnss` if fitted.
    pub(crate) fn new(line: SerialLine, imu_rate_hz: f64, gnss: Option<GnssDevice>) -> Self {
        Self {
            line,
            outage: Outage::default(),
            imu_rate_hz,
            gnss,
        }
    }

    /// Unplugs the line before the next step, so that step's frames are the first lost.
    fn disconnect(&mut self, sim: &Simulator, command: &Disconnect) -> FaultApplied {
        if self
            .outage
            .begin(sim.tick(), command.ticks(self.imu_rate_hz))
        {
            self.line.unplug();
            tracing::info!(fault = %command, time_s = sim.time_s(), "serial line unplugged");
        } else {
            tracing::info!(fault = %command, time_s = sim.time_s(), "serial line outage extended");
        }
        FaultApplied {
            outcome: FaultOutcome::Applied as u8,
            device_time_us: next_sample_time_us(sim),
            ..fault_event(&SimCommand::Disconnect(*command).to_control())
        }
    }

    /// Plugs the line back in when its outage is over; a failure is logged and retried.
    pub(crate) fn reconnect_if_due(&mut self, sim: &Simulator) {
        if !self.outage.due(sim.tick()) {
            return;
        }
        match self.line.plug() {
            Ok(tty) => {
                tracing::info!(port = %tty, time_s = sim.time_s(), "serial line plugged back in");
                // Whoever started a stand-alone simulator reads the device path here; nobody
                // reading it is no reason to stop.
                let mut out = std::io::stdout().lock();
                let _ = writeln!(out, "{tty}").and_then(|()| out.flush());
                self.outage.end();
            }
            Err(e) => {
                let retry = (PLUG_RETRY_S * self.imu_rate_hz).ceil() as u64;
                tracing::error!(
                    error = %e,
                    retry_s = PLUG_RETRY_S,
                    "cannot plug the serial line back in"
                );
                self.outage.retry_at(sim.tick() + retry.max(1));
            }
        }
    }

    /// Applies any command before the next step.
    pub(crate) fn apply(
        &mut self,
        sim: &mut Simulator,
        command: &SimCommand,
        noise: &WhiteNoise,
    ) -> FaultApplied {
        match command {
            SimCommand::Channel(c) => apply_fault(sim, c, noise),
            SimCommand::Disconnect(d) => self.disconnect(sim, d),
            SimCommand::Gnss { fault, param } => {
                let outcome = match &mut self.gnss {
                    Some(gnss) => gnss.apply(sim, *fault, *param),
                    None => {
                        tracing::warn!(
                            fault = fault.name(),
                            "no GNSS receiver is simulated: fault ignored"
                        );
                        FaultOutcome::NoSuchChannel
                    }
                };
                FaultApplied {
                    outcome: outcome as u8,
                    device_time_us: next_sample_time_us(sim),
                    ..fault_event(&command.to_control())
                }
            }
        }
    }

    /// Applies a command received on [`ipc_types::names::SIM_CONTROL`]; malformed ones are logged and
    /// ignored.
    pub(crate) fn handle_control(
        &mut self,
        sim: &mut Simulator,
        control: &SimControl,
        noise: &WhiteNoise,
    ) -> FaultApplied {
        match SimCommand::from_control(control) {
            Ok(command) => self.apply(sim, &command, noise),
            Err(e) => rejected(sim, control, e),
        }
    }
}

/// Logs a command the simulator refused and describes the refusal.
fn rejected(sim: &Simulator, control: &SimControl, e: ControlError) -> FaultApplied {
    let outcome = match e {
        ControlError::Unknown => FaultOutcome::UnknownCommand,
        ControlError::NoSuchChannel => FaultOutcome::NoSuchChannel,
        ControlError::InvalidParameter => FaultOutcome::InvalidParameter,
    };
    tracing::warn!(
        version = control.version,
        sensor = control.sensor,
        channel = control.channel,
        fault = control.fault,
        param = control.param,
        outcome = outcome.name(),
        "simulator control command ignored"
    );
    FaultApplied {
        outcome: outcome as u8,
        device_time_us: next_sample_time_us(sim),
        ..fault_event(control)
    }
}
