//! The simulator process: a pseudo-terminal that behaves like the sensor block's serial line, fed in
//! real time, plus the truth topic for accuracy checks.

use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result};
use ipc_types::{Header, Health, PAYLOAD_VERSION, ServiceKind, Truth, names};
use rins_acquisition::protocol::{Frame, MAX_FRAME_LEN, encode};
use rins_runtime::clock::monotonic_ns;
use rins_runtime::heartbeat::Heartbeat;
use rins_runtime::ipc::{IpcSettings, TopicPublisher, create_node};
use rins_runtime::shutdown::Shutdown;
use serialport::{SerialPort, TTYPort};

use crate::simulator::{Simulator, TickOutput, TruthSample};

/// Frames of one tick at most: IMU, baro, mag, aux.
const FRAMES_PER_TICK: usize = 4;
/// How long a write may wait for the reader before the tick's bytes are dropped (a real line
/// would overrun the receiver the same way).
const WRITE_TIMEOUT: Duration = Duration::from_millis(2);

pub struct SimOptions {
    /// Also expose the pseudo-terminal under this path (a stable name for acquisition).
    pub link: Option<PathBuf>,
    /// Stop after this many seconds of device time.
    pub duration_s: Option<f64>,
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
