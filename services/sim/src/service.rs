//! The simulator process: a pseudo-terminal that behaves like the sensor block's serial line, fed in
//! real time, plus the truth topic for accuracy checks. The line can be unplugged for a while on
//! command ([`SimCommand::Disconnect`]).

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use ipc_types::{
    FaultApplied, FaultOutcome, Header, Health, PAYLOAD_VERSION, ServiceKind, SimControl, SimFault,
    Truth, names,
};
use rins_protocol::{Frame, MAX_FRAME_LEN, encode};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{TopicPublisher, TopicSubscriber};
use rins_runtime::service::{Service, ServiceContext};

use crate::device_fault::Disconnect;
use crate::fault_command::{ControlError, FaultCommand, WhiteNoise};
use crate::fault_schedule::{FaultSchedule, ScheduledFault};
use crate::gnss_receiver::GnssReceiver;
use crate::outage::Outage;
use crate::serial_line::SerialLine;
use crate::sim_command::SimCommand;
use crate::simulator::{Simulator, TickOutput, TruthSample};

/// Frames of one tick at most: IMU, baro, mag, aux.
const FRAMES_PER_TICK: usize = 4;
/// When a new pseudo-terminal cannot be made, the next try comes this much device time later.
const PLUG_RETRY_S: f64 = 0.1;

/// How the simulator process runs, beside the simulated device itself.
pub struct SimOptions {
    /// Also expose the pseudo-terminal under this path (a stable name for acquisition).
    pub link: Option<PathBuf>,
    /// Stop after this many seconds of device time.
    pub duration_s: Option<f64>,
    /// Faults to apply at given device times.
    pub faults: Vec<ScheduledFault>,
    /// Configured white noise, the unit of noise-factor faults.
    pub noise: WhiteNoise,
    /// The simulated GNSS receiver on its own terminal, when one is fitted.
    pub gnss: Option<GnssOptions>,
}

/// The simulated GNSS receiver's settings and its terminal's stable name.
pub struct GnssOptions {
    /// `[sim.gnss]`.
    pub config: crate::gnss_config::GnssReceiverConfig,
    /// Also expose the receiver's pseudo-terminal under this path.
    pub link: Option<PathBuf>,
    /// Seed of its noise (mixed with a salt of its own).
    pub seed: u64,
}

/// The receiver and its line.
struct GnssDevice {
    receiver: GnssReceiver,
    line: SerialLine,
    /// Bytes of the tick, reused.
    buf: Vec<u8>,
}

impl GnssDevice {
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
    fn tick(&mut self, truth: &crate::simulator::TruthSample) {
        self.buf.clear();
        self.receiver.tick(truth, &mut self.buf);
        if !self.buf.is_empty() {
            // Nobody reading (the gnss service restarting): the epoch is lost, as on a real line.
            let _ = self.line.send(&self.buf);
        }
    }
}

/// The truth topic's sample for one tick of the simulated trajectory.
pub fn truth_message(t: &TruthSample) -> Truth {
    Truth {
        version: PAYLOAD_VERSION,
        header: Header {
            origin_seq: t.imu_seq,
            origin_device_time_us: t.device_time_us,
            ..Header::default()
        },
        quaternion: t.quaternion,
        velocity_ned_mps: t.velocity_ned_mps,
        latitude_rad: t.latitude_rad,
        longitude_rad: t.longitude_rad,
        altitude_m: t.altitude_m,
        ..Truth::default()
    }
}

/// Sleeps until CLOCK_MONOTONIC reaches `deadline_ns`.
fn sleep_until(deadline_ns: u64) {
    let ts = libc::timespec {
        tv_sec: (deadline_ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (deadline_ns % 1_000_000_000) as libc::c_long,
    };
    // SAFETY: absolute sleep on the monotonic clock; an interrupted sleep just returns early and the
    // caller's next deadline check handles it.
    unsafe {
        libc::clock_nanosleep(
            libc::CLOCK_MONOTONIC,
            libc::TIMER_ABSTIME,
            &ts,
            std::ptr::null_mut(),
        );
    }
}

/// Encodes the frames of one tick into `buf`, returning the byte count.
fn encode_tick(out: &TickOutput, buf: &mut [u8]) -> usize {
    let frames: [Option<&Frame>; FRAMES_PER_TICK] = [
        Some(&out.imu),
        out.baro.as_ref(),
        out.mag.as_ref(),
        out.aux.as_ref(),
    ];
    let mut len = 0;
    for frame in frames.into_iter().flatten() {
        // The simulator only produces valid frames, and the buffer holds four of the largest.
        if let Ok(n) = encode(frame, &mut buf[len..]) {
            len += n;
        }
    }
    len
}

/// Device time of the sample the next step produces, µs (as [`Simulator::step`] stamps it).
fn next_sample_time_us(sim: &Simulator) -> u64 {
    (sim.tick() as f64 * sim.imu_period_s() * 1e6).round() as u64
}

/// Applies one channel fault before the next step, so it affects that step's sample, and
/// describes what happened for [`names::SIM_FAULT_APPLIED`].
fn apply_fault(sim: &mut Simulator, command: &FaultCommand, noise: &WhiteNoise) -> FaultApplied {
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
struct Device {
    line: SerialLine,
    outage: Outage,
    imu_rate_hz: f64,
    gnss: Option<GnssDevice>,
}

impl Device {
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
    fn reconnect_if_due(&mut self, sim: &Simulator) {
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
    fn apply(
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

    /// Applies a command received on [`names::SIM_CONTROL`]; malformed ones are logged and
    /// ignored.
    fn handle_control(
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

/// The simulator process: the simulated device and how it runs, ready to stream.
pub struct SimService {
    /// The simulated sensor block.
    pub sim: Simulator,
    /// Link, duration, scheduled faults, noise unit.
    pub options: SimOptions,
}

impl Service for SimService {
    fn run(self, ctx: ServiceContext) -> Result<()> {
        run(self.sim, &self.options, &ctx)
    }
}

/// Streams the device in real time until `ctx.shutdown` or the configured duration.
fn run(mut sim: Simulator, options: &SimOptions, ctx: &ServiceContext) -> Result<()> {
    let shutdown = &ctx.shutdown;
    let line = SerialLine::open(options.link.clone())?;
    let tty = line.tty().unwrap_or_default();
    // Without a link the path is how a person finds the device to read it; with one (under
    // `rins up`) the link is the device's name and the log line below carries the path.
    if options.link.is_none() {
        println!("{tty}");
        let _ = std::io::stdout().flush();
    }
    tracing::info!(port = %tty, link = ?options.link, "simulated sensor block streaming");

    // Sleep precisely: the default 50 µs timer slack would show up as frame jitter.
    // SAFETY: prctl on our own process with a plain integer argument.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };

    let node = ctx.create_node(ServiceKind::Simulator)?;
    let truth = TopicPublisher::<Truth>::new(&node, names::TRUTH)?;
    let fault_events = TopicPublisher::<FaultApplied>::new(&node, names::SIM_FAULT_APPLIED)?;
    let control = TopicSubscriber::<SimControl>::new(&node, names::SIM_CONTROL)?;
    let imu_rate_hz = 1.0 / sim.imu_period_s();
    let mut schedule = FaultSchedule::new(&options.faults, imu_rate_hz);
    let gnss = match &options.gnss {
        Some(g) => {
            let line = SerialLine::open(g.link.clone())?;
            tracing::info!(port = line.tty().unwrap_or_default(), link = ?g.link, "simulated GNSS receiver streaming");
            Some(GnssDevice {
                receiver: GnssReceiver::new(g.config, g.seed),
                line,
                buf: Vec::with_capacity(1024),
            })
        }
        None => None,
    };
    let mut device = Device {
        line,
        outage: Outage::default(),
        imu_rate_hz,
        gnss,
    };
    let mut heartbeat = Heartbeat::new(&node, ServiceKind::Simulator)?;
    let mut counters = Health::default();
    let mut out = TickOutput::default();
    let mut buf = [0u8; FRAMES_PER_TICK * MAX_FRAME_LEN];
    let period_ns = (sim.imu_period_s() * 1e9).round() as u64;
    let start_ns = monotonic_ns();
    let end_tick = options
        .duration_s
        .map(|d| (d / sim.imu_period_s()).ceil() as u64);

    while !shutdown.requested() && end_tick.is_none_or(|end| sim.tick() < end) {
        sleep_until(start_ns + sim.tick() * period_ns);
        device.reconnect_if_due(&sim);
        // Faults first, announced before the frame leaves: whoever measures detection delays
        // must know of a fault before any output derived from the faulty sample.
        while let Some(command) = schedule.next_due(sim.tick()) {
            fault_events.publish(device.apply(&mut sim, &command, &options.noise))?;
        }
        while let Some(command) = control.receive()? {
            fault_events.publish(device.handle_control(&mut sim, &command, &options.noise))?;
        }
        sim.step(&mut out);
        // Truth first: whoever compares against it must find it before the frame's navigation output.
        truth.publish(truth_message(&out.truth))?;
        if let Some(gnss) = &mut device.gnss {
            gnss.tick(&out.truth);
        }
        let len = encode_tick(&out, &mut buf);
        // Unplugged, or nobody reads the line (acquisition restarting): the frames are lost, and
        // the device's time and sequence numbers go on regardless.
        if device.line.send(&buf[..len]) {
            counters.published += 1;
        } else {
            counters.lost += 1;
        }
        heartbeat.tick(&counters)?;
    }
    // Dropping the line removes the link.
    drop(device);
    Ok(())
}
