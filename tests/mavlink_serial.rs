//! MAVLink over a serial port as an autopilot's TELEM port sees it: `rins up --mavlink
//! serial:PATH:BAUD` writes the stream to a pseudo-terminal, and the test, at the other end, reads
//! HEARTBEAT, ODOMETRY and SYS_STATUS with valid checksums; SYS_STATUS's load is the pipeline's
//! CPU, which a running pipeline never has at 0. A baud rate or endpoint that cannot be used stops
//! the start with an error naming it.

mod common;

use std::io::Read;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, TempFile, fails_with, spawn_up, stop_up};
use mavlink::{MavlinkReader, MavlinkVersion};
use rins_mavlink::dialect::MavMessage;
use serialport::{SerialPort, TTYPort};

/// A running pipeline on a loaded machine may take this long to start streaming.
const START: Duration = Duration::from_secs(90);

/// The terminal's master end, for the MAVLink reader: a read that times out is no end of stream;
/// counts the bytes (the line rate the stream needs).
struct Patient(TTYPort, Arc<AtomicU64>);

impl Read for Patient {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        loop {
            match self.0.read(buf) {
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Ok(n) => {
                    self.1.fetch_add(n as u64, Relaxed);
                    return Ok(n);
                }
                other => return other,
            }
        }
    }
}

#[test]
fn a_pipeline_streams_to_a_serial_port_with_its_cpu_load() {
    let ipc = Isolated::new("mavserial");
    let _slot = PipelineSlot::take();
    let (mut master, slave) = TTYPort::pair().expect("a pseudo-terminal");
    master.set_timeout(Duration::from_millis(200)).unwrap();
    let tty = slave.name().expect("the terminal's name");
    let endpoint = format!("serial:{tty}:921600");
    let up = spawn_up(&ipc, &["--mavlink", &endpoint, "--json"]);
    // Read on a thread: the pipeline is stopped from here once enough has arrived, or the time
    // is up.
    let (tx, rx) = std::sync::mpsc::channel();
    let bytes = Arc::new(AtomicU64::new(0));
    let counted = Arc::clone(&bytes);
    let reader = std::thread::spawn(move || {
        let mut reader = MavlinkReader::new(Patient(master, counted));
        // Only frames with a valid checksum come out of the reader.
        while let Ok((header, msg)) = reader.read_message::<MavMessage>(MavlinkVersion::V2) {
            if tx.send((header, msg)).is_err() {
                return;
            }
        }
    });
    let deadline = Instant::now() + START;
    let (mut heartbeats, mut odometry, mut loads) = (0, 0, Vec::new());
    // The byte rate from the first SYS_STATUS on, when every stream runs.
    let mut since: Option<(Instant, u64)> = None;
    while Instant::now() < deadline && !(heartbeats >= 2 && odometry >= 10 && loads.len() >= 6) {
        let Ok((header, msg)) = rx.recv_timeout(Duration::from_secs(1)) else {
            continue;
        };
        assert_eq!(header.system_id, 1);
        match msg {
            MavMessage::HEARTBEAT(_) => heartbeats += 1,
            MavMessage::ODOMETRY(_) => odometry += 1,
            MavMessage::SYS_STATUS(s) => {
                loads.push(s.load);
                since.get_or_insert((Instant::now(), bytes.load(Relaxed)));
            }
            _ => {}
        }
    }
    let rate = since.map(|(t, b)| (bytes.load(Relaxed) - b) as f64 / t.elapsed().as_secs_f64());
    drop(rx);
    let summary = stop_up(&ipc, up);
    drop(slave);
    let _ = reader.join();
    eprintln!(
        "heartbeats {heartbeats}, odometry {odometry}, SYS_STATUS loads {loads:?}, \
         {rate:?} bytes/s on the line"
    );
    eprintln!("{summary}");
    assert!(heartbeats >= 2 && odometry >= 10, "{}", ipc.up_stderr());
    // The first SYS_STATUS may come before the first interval is measured; the later ones carry
    // the pipeline's CPU: six processes at work, at least one clock tick in a half-second
    // interval, which is more than 0 ‰ however many processors there are.
    assert!(loads.len() >= 6, "{loads:?}");
    assert!(
        loads.iter().skip(2).all(|&l| l > 0 && l <= 1000),
        "{loads:?}"
    );
}

#[test]
fn serial_endpoints_that_cannot_be_used_are_named() {
    fails_with(
        "mavserial-baud",
        &[
            "up",
            "--mavlink",
            "serial:/dev/ttyS1:92160",
            "--duration",
            "1",
        ],
        &[
            "--mavlink \"serial:/dev/ttyS1:92160\"",
            "92160 is not a standard rate",
        ],
    );
    fails_with(
        "mavserial-path",
        &["up", "--mavlink", "serial:ttyS1:57600", "--duration", "1"],
        &["serial:ttyS1:57600", "not absolute"],
    );
    let config = rins::config::BUILT_IN.replace(
        "endpoints = [\"udpout:127.0.0.1:14550\"]",
        "endpoints = [\"serial:/dev/ttyS1:57601\"]",
    );
    assert!(config.contains("serial:/dev/ttyS1:57601"));
    let file = TempFile::new("mavserial", "toml", &config);
    fails_with(
        "mavserial-config",
        &["up", "--config", file.path(), "--duration", "1"],
        &[
            "mavlink.endpoints[0] = \"serial:/dev/ttyS1:57601\"",
            "57601 is not a standard rate",
        ],
    );
}
