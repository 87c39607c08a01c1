//! A sensor block played by the test: the simulator's frames, tampered with as the test likes, written
//! to a pseudo-terminal at the device's own rate. It speaks the wire protocol (docs/protocol.md)
//! through the acquisition's encoder, so it can send any frame the protocol can carry — a valid CRC
//! around content no healthy device would send — and raw bytes besides.

#![allow(dead_code)]

use std::io::Write;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rins_protocol::layout::{HEADER_LEN, SYNC, TYPE_OFFSET};
use rins_protocol::{Frame, MAX_FRAME_LEN, encode};
use rins_sim::{Scenario, Simulator, TickOutput};
use serialport::{SerialPort, TTYPort};

/// One IMU period of the device, handed to the test's tamper function before it is written.
pub struct DeviceTick<'a> {
    /// Device seconds since the device started (IMU tick / IMU rate).
    pub t_s: f64,
    /// The frames of this tick, IMU first, then baro, magnetometer, auxiliary when due. The tamper
    /// may change, reorder, add or remove them.
    pub frames: &'a mut Vec<Frame>,
    /// Bytes written after the frames (garbage, hand-made frames); empty on entry.
    pub raw: &'a mut Vec<u8>,
}

/// A device on a pseudo-terminal, writing until dropped.
pub struct FakeDevice {
    tty: String,
    stop: Arc<AtomicBool>,
    /// Device time reached, µs (for tests that wait on the device's clock).
    device_us: Arc<AtomicU64>,
    thread: Option<JoinHandle<()>>,
}

/// Content no healthy device sends, inside a frame whose CRC is valid (docs/protocol.md, decoding
/// steps 1 and 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Malformed {
    /// Type byte 9: no such frame type.
    UnknownType,
    /// A baro frame announcing 7 payload bytes (it has 6).
    BadLength,
    /// An IMU frame with one gyro channel at 3000 counts (12 bits reach 2047).
    CountBeyond12Bits,
    /// An IMU frame announcing 17 gyro channels (16 at most).
    TooManyChannels,
}

impl Malformed {
    pub const ALL: [Malformed; 4] = [
        Malformed::UnknownType,
        Malformed::BadLength,
        Malformed::CountBeyond12Bits,
        Malformed::TooManyChannels,
    ];
}

/// The bytes of one frame with a valid CRC-32C around `kind`'s malformed content; sequence number
/// and device time 0. The bytes hold no second sync word, so a decoder rejects exactly one frame.
pub fn malformed_frame(kind: Malformed) -> Vec<u8> {
    let (frame_type, payload): (u8, Vec<u8>) = match kind {
        Malformed::UnknownType => (9, vec![1, 2]),
        Malformed::BadLength => (2, vec![0; 7]),
        Malformed::CountBeyond12Bits => {
            // n_gyro 1, n_accel 0, n_temperature 0, status 0, valid_mask 1, then the count.
            let mut p = vec![1, 0, 0, 0, 0, 1, 0, 0, 0];
            p.extend(3000i16.to_le_bytes());
            (1, p)
        }
        Malformed::TooManyChannels => (1, vec![17, 0, 0, 0, 0, 0, 0, 0, 0]),
    };
    let mut bytes = SYNC.to_vec();
    bytes.push(frame_type);
    bytes.push(u8::try_from(payload.len()).expect("short payload"));
    bytes.extend([0u8; HEADER_LEN - 4]); // sequence number and device time
    bytes.extend(&payload);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISCSI).checksum(&bytes[TYPE_OFFSET..]);
    bytes.extend(crc.to_le_bytes());
    assert!(
        !bytes[1..].windows(2).any(|w| w == SYNC),
        "{kind:?}: a second sync word in {bytes:02X?}"
    );
    bytes
}

/// How long one write may wait for the reader before the tick's bytes are dropped (the terminal
/// holds a few dozen ms of frames; the pipeline may not have opened it yet).
const WRITE_TIMEOUT: Duration = Duration::from_millis(50);

impl FakeDevice {
    /// Starts the built-in sensor block flying `scenario` (seed 1), each tick passed through
    /// `tamper` before it is written.
    pub fn start(scenario: Scenario, tamper: impl FnMut(DeviceTick) + Send + 'static) -> Self {
        Self::start_with(scenario, Link::Lossy, tamper)
    }

    /// [`FakeDevice::start`] on a line that waits for a slow reader instead of dropping bytes (a
    /// device with flow control), for tests that count losses exactly on a loaded machine.
    pub fn start_lossless(
        scenario: Scenario,
        tamper: impl FnMut(DeviceTick) + Send + 'static,
    ) -> Self {
        Self::start_with(scenario, Link::Lossless, tamper)
    }

    fn start_with(
        scenario: Scenario,
        link: Link,
        tamper: impl FnMut(DeviceTick) + Send + 'static,
    ) -> Self {
        let mut cfg = rins::config::load(None).expect("built-in configuration");
        cfg.sim.scenario = scenario;
        let (gyro, accel) = cfg.geometries().expect("built-in geometries");
        let sim = Simulator::new(&cfg.sim, gyro.axes(), accel.axes(), 1).expect("simulator");
        let (mut master, slave) = TTYPort::pair().expect("cannot create a pseudo-terminal");
        let tty = slave.name().expect("pseudo-terminal name");
        master
            .set_timeout(WRITE_TIMEOUT)
            .expect("pseudo-terminal timeout");
        let stop = Arc::new(AtomicBool::new(false));
        let device_us = Arc::new(AtomicU64::new(0));
        let thread = {
            let (stop, device_us) = (Arc::clone(&stop), Arc::clone(&device_us));
            std::thread::spawn(move || {
                // Held open so that the terminal outlives a reader that closes it.
                let _slave = slave;
                write_loop(sim, master, link, tamper, &stop, &device_us);
            })
        };
        Self {
            tty,
            stop,
            device_us,
            thread: Some(thread),
        }
    }

    /// The terminal's device path, for `rins up --port`.
    pub fn tty(&self) -> &str {
        &self.tty
    }

    /// Device seconds written so far.
    pub fn device_time_s(&self) -> f64 {
        self.device_us.load(Ordering::Relaxed) as f64 * 1e-6
    }
}

impl Drop for FakeDevice {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// What the line does with bytes a reader does not take within [`WRITE_TIMEOUT`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Link {
    /// Drops them, as a serial line without flow control.
    Lossy,
    /// Waits (until the device is dropped).
    Lossless,
}

fn write_loop(
    mut sim: Simulator,
    mut port: TTYPort,
    link: Link,
    mut tamper: impl FnMut(DeviceTick),
    stop: &AtomicBool,
    device_us: &AtomicU64,
) {
    let period = Duration::from_secs_f64(sim.imu_period_s());
    let start = Instant::now();
    let mut out = TickOutput::default();
    let (mut frames, mut raw, mut bytes) = (Vec::new(), Vec::new(), Vec::new());
    let mut buf = [0u8; MAX_FRAME_LEN];
    while !stop.load(Ordering::Relaxed) {
        // Every tick due by now, in one write: the device's rate on average, whatever the sleeps.
        let due = (start.elapsed().as_secs_f64() / period.as_secs_f64()) as u64 + 1;
        bytes.clear();
        while sim.tick() < due {
            let t_s = sim.time_s();
            sim.step(&mut out);
            frames.clear();
            raw.clear();
            frames.extend(out.frames().into_iter().flatten().copied());
            tamper(DeviceTick {
                t_s,
                frames: &mut frames,
                raw: &mut raw,
            });
            for frame in &frames {
                // A frame the encoder refuses (counts beyond 12 bits) is the tamper's mistake.
                let n = encode(frame, &mut buf).expect("tampered frame cannot be encoded");
                bytes.extend_from_slice(&buf[..n]);
            }
            bytes.extend_from_slice(&raw);
            device_us.store(out.truth.device_time_us, Ordering::Relaxed);
        }
        // A reader that is not there yet (or too slow) loses these bytes, as on a real line.
        match link {
            Link::Lossy => {
                let _ = port.write_all(&bytes);
            }
            Link::Lossless => {
                let mut rest = bytes.as_slice();
                while !rest.is_empty() && !stop.load(Ordering::Relaxed) {
                    match port.write(rest) {
                        Ok(n) => rest = &rest[n..],
                        Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                        Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                        Err(_) => break,
                    }
                }
            }
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}
