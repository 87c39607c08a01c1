//! The simulator process: a pseudo-terminal that behaves like the sensor block's serial line, fed in
//! real time, plus the truth topic for accuracy checks.

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result};
use ipc_types::{
    FaultApplied, FaultOutcome, Header, Health, PAYLOAD_VERSION, ServiceKind, SimControl, Truth,
    names,
};
use rins_acquisition::protocol::{Frame, MAX_FRAME_LEN, encode};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, TopicSubscriber, create_node};
use rins_runtime::shutdown::Shutdown;
use serialport::{SerialPort, TTYPort};

use crate::fault_command::{ControlError, FaultCommand, WhiteNoise};
use crate::fault_schedule::{FaultSchedule, ScheduledFault};
use crate::simulator::{Simulator, TickOutput, TruthSample};

/// Frames of one tick at most: IMU, baro, mag, aux.
const FRAMES_PER_TICK: usize = 4;
/// How long a write may wait for the reader before the tick's bytes are dropped. The pty holds
/// about 40 ms of frames; past that a real line would overrun the receiver. The simulator waits
/// longer than a real device would, because it shares the processor with the pipeline it feeds: a
/// stalled reader on a loaded machine delays frames (the sleeps catch up) instead of losing them.
const WRITE_TIMEOUT: Duration = Duration::from_millis(100);

pub struct SimOptions {
    /// Also expose the pseudo-terminal under this path (a stable name for acquisition).
    pub link: Option<PathBuf>,
    /// Stop after this many seconds of device time.
    pub duration_s: Option<f64>,
    /// Faults to apply at given device times.
    pub faults: Vec<ScheduledFault>,
    /// Configured white noise, the unit of noise-factor faults.
    pub noise: WhiteNoise,
}

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

/// Applies one fault command before the next step, so it affects that step's sample, and
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

/// Applies a command received on [`names::SIM_CONTROL`]; malformed ones are logged and ignored.
fn handle_control(sim: &mut Simulator, control: &SimControl, noise: &WhiteNoise) -> FaultApplied {
    match FaultCommand::from_control(control) {
        Ok(command) => apply_fault(sim, &command, noise),
        Err(e) => {
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
    }
}

pub fn run(
    mut sim: Simulator,
    options: &SimOptions,
    settings: &IpcSettings,
    shutdown: &Shutdown,
) -> Result<()> {
    let (mut master, slave) = TTYPort::pair().context("cannot create a pseudo-terminal")?;
    let tty = slave
        .name()
        .context("the pseudo-terminal has no device name")?;
    master.set_timeout(WRITE_TIMEOUT)?;
    if let Some(link) = &options.link {
        let _ = std::fs::remove_file(link);
        std::os::unix::fs::symlink(&tty, link)
            .with_context(|| format!("cannot link {} to {tty}", link.display()))?;
    }
    println!("{tty}");
    let _ = std::io::stdout().flush();
    tracing::info!(port = %tty, link = ?options.link, "simulated sensor block streaming");

    // Sleep precisely: the default 50 µs timer slack would show up as frame jitter.
    // SAFETY: prctl on our own process with a plain integer argument.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };

    let node = create_node("sim", settings)?;
    let truth = TopicPublisher::<Truth>::new(&node, names::TRUTH)?;
    let fault_events = TopicPublisher::<FaultApplied>::new(&node, names::SIM_FAULT_APPLIED)?;
    let control = TopicSubscriber::<SimControl>::new(&node, names::SIM_CONTROL)?;
    let mut schedule = FaultSchedule::new(&options.faults, 1.0 / sim.imu_period_s());
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
        // Faults first, announced before the frame leaves: whoever measures detection delays
        // must know of a fault before any output derived from the faulty sample.
        while let Some(command) = schedule.next_due(sim.tick()) {
            fault_events.publish(apply_fault(&mut sim, &command, &options.noise))?;
        }
        while let Some(command) = control.receive()? {
            fault_events.publish(handle_control(&mut sim, &command, &options.noise))?;
        }
        sim.step(&mut out);
        // Truth first: whoever compares against it must find it before the frame's navigation output.
        truth.publish(truth_message(&out.truth))?;
        let len = encode_tick(&out, &mut buf);
        match master.write_all(&buf[..len]) {
            Ok(()) => counters.published += 1,
            // Nobody reads the line (acquisition restarting): the device's frames are lost.
            Err(_) => counters.lost += 1,
        }
        heartbeat.tick(&counters)?;
    }
    drop(slave);
    if let Some(link) = &options.link {
        let _ = std::fs::remove_file(link);
    }
    Ok(())
}
