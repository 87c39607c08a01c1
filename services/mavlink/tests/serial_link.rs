//! The link over a serial port, on a pseudo-terminal standing in for the autopilot's TELEM port:
//! what rins writes arrives as back-to-back MAVLink 2 frames with valid checksums and consecutive
//! sequence numbers; TIMESYNC is answered and commands come through on the same wire; a port that
//! disappears (an unplugged USB adapter) is counted, reopened once it is back, and the stream goes
//! on.
//!
//! The port is reached through a symlink, as through `/dev/serial/by-id/...`: unplugging removes
//! it and closes the terminal, plugging in makes a new terminal and points the link at it.

use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering::Relaxed;
use std::time::{Duration, Instant};

use mavlink::{MAVLinkV2MessageRaw, MavHeader, MavlinkVersion, Message};
use rins_mavlink::command_gate::CommandGate;
use rins_mavlink::config::MavlinkConfig;
use rins_mavlink::dialect::{COMMAND_LONG_DATA, MavCmd, MavMessage, ODOMETRY_DATA, TIMESYNC_DATA};
use rins_mavlink::endpoint::Endpoint;
use rins_mavlink::heartbeat::{Profile, heartbeat};
use rins_mavlink::link::{Link, LinkSecurity};
use serialport::{SerialPort, TTYPort};

const WAIT: Duration = Duration::from_secs(5);
/// rins on the link.
const RINS: (u8, u8) = (1, 197);
/// The autopilot at the other end of the wire.
const AUTOPILOT: (u8, u8) = (1, 1);

/// A pseudo-terminal plugged in under a symlink: the test holds the master (the autopilot's end)
/// and the slave, so that the terminal outlives the link's opening and closing it.
struct Plug {
    master: TTYPort,
    _slave: TTYPort,
}

fn plug(link: &Path) -> Plug {
    let (mut master, slave) = TTYPort::pair().expect("a pseudo-terminal");
    master.set_timeout(Duration::from_millis(100)).unwrap();
    let tty = slave.name().expect("the terminal's name");
    let tmp = link.with_extension("new");
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(&tty, &tmp).unwrap();
    std::fs::rename(&tmp, link).unwrap();
    Plug {
        master,
        _slave: slave,
    }
}

/// A directory of the test's own for the symlink.
struct Dir(PathBuf);

impl Dir {
    fn new(tag: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("rins-serial-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A link streaming to the serial port at `path`, taking unsigned commands from anyone; the
/// address rule is set, and does not apply to a wire.
fn start(path: &Path) -> Link {
    let config = MavlinkConfig {
        accept_commands: true,
        allow_unsigned_commands: true,
        command_addresses: vec!["192.0.2.1".into()],
        ..MavlinkConfig::default()
    };
    let endpoint = Endpoint::parse(&format!("serial:{}:921600", path.display())).unwrap();
    Link::start(
        &[endpoint],
        RINS,
        64,
        LinkSecurity {
            key: None,
            link_id: 0,
            gate: CommandGate::new(&config, false),
        },
    )
    .unwrap()
}

/// Reads the autopilot's end: whole frames, one after another with nothing between them, each
/// with a valid checksum, until `done` says enough or [`WAIT`] passes. The messages and their
/// sequence numbers.
fn read_frames(
    master: &mut TTYPort,
    mut done: impl FnMut(&[MavMessage]) -> bool,
) -> Vec<(u8, MavMessage)> {
    let deadline = Instant::now() + WAIT;
    let mut bytes = Vec::new();
    let mut messages = Vec::new();
    let mut seen = Vec::new();
    let mut chunk = [0u8; 512];
    while Instant::now() < deadline && !done(&seen) {
        match master.read(&mut chunk) {
            Ok(n) => bytes.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
            Err(e) => panic!("reading the terminal: {e}"),
        }
        // Every whole frame at the front.
        while bytes.len() >= 12 {
            assert_eq!(bytes[0], 0xfd, "a frame must start here: {bytes:x?}");
            let signed = bytes[2] & 1 != 0;
            let len = 12 + usize::from(bytes[1]) + if signed { 13 } else { 0 };
            if bytes.len() < len {
                break;
            }
            let mut raw = MAVLinkV2MessageRaw::new();
            raw.as_mut_slice()[..len].copy_from_slice(&bytes[..len]);
            assert!(raw.has_valid_crc::<MavMessage>(), "checksum of {raw:?}");
            let msg = MavMessage::parse(MavlinkVersion::V2, raw.message_id(), raw.payload())
                .expect("a message of the common set");
            assert_eq!((raw.system_id(), raw.component_id()), (1, RINS.1));
            messages.push((raw.sequence(), msg.clone()));
            seen.push(msg);
            bytes.drain(..len);
        }
    }
    messages
}

/// `msg` from the autopilot as one frame.
fn frame(msg: &MavMessage) -> Vec<u8> {
    let header = MavHeader {
        system_id: u32::from(AUTOPILOT.0),
        component_id: AUTOPILOT.1,
        sequence: 0,
    };
    let mut bytes = Vec::new();
    mavlink::write_v2_msg(&mut bytes, header, msg).unwrap();
    bytes
}

fn has(seen: &[MavMessage], id: u32) -> bool {
    seen.iter().any(|m| m.message_id() == id)
}

const HEARTBEAT: u32 = 0;
const ODOMETRY: u32 = 331;
const TIMESYNC: u32 = 111;

#[test]
fn the_stream_reaches_the_wire_whole_and_answers_come_back_on_it() {
    let dir = Dir::new("stream");
    let path = dir.0.join("telem");
    let mut port = plug(&path);
    let link = start(&path);
    // The reader opens the port on its own thread: wait until a frame gets through.
    let deadline = Instant::now() + WAIT;
    while link.counters.sent.load(Relaxed) == 0 && Instant::now() < deadline {
        link.queue(MavMessage::HEARTBEAT(heartbeat(Profile::Onboard, None)));
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(link.counters.sent.load(Relaxed) > 0, "nothing written");
    for _ in 0..20 {
        link.queue(MavMessage::ODOMETRY(ODOMETRY_DATA {
            time_usec: 42,
            ..ODOMETRY_DATA::default()
        }));
        link.queue(MavMessage::HEARTBEAT(heartbeat(Profile::Onboard, None)));
    }
    // The autopilot asks for the time and sends a command on the same wire.
    port.master
        .write_all(&frame(&MavMessage::TIMESYNC(TIMESYNC_DATA {
            tc1: 0,
            ts1: 123_456_789,
            ..TIMESYNC_DATA::default()
        })))
        .unwrap();
    port.master
        .write_all(&frame(&MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
            target_system: RINS.0,
            target_component: RINS.1,
            command: MavCmd::MAV_CMD_USER_1,
            param2: 2.0,
            ..COMMAND_LONG_DATA::default()
        })))
        .unwrap();
    // Read until the answer and every queued frame are in: the last queued is the heartbeat after
    // the 20th odometry, and the answer, written by the reader at once, may overtake it.
    let frames = read_frames(&mut port.master, |seen| {
        let queued_heartbeats = seen
            .iter()
            .skip_while(|m| m.message_id() != ODOMETRY)
            .filter(|m| m.message_id() == HEARTBEAT)
            .count();
        has(seen, TIMESYNC)
            && seen.iter().filter(|m| m.message_id() == ODOMETRY).count() == 20
            && queued_heartbeats >= 20
    });
    let seen: Vec<MavMessage> = frames.iter().map(|(_, m)| m.clone()).collect();
    assert!(has(&seen, HEARTBEAT) && has(&seen, ODOMETRY), "{seen:?}");
    assert!(
        seen.iter()
            .any(|m| matches!(m, MavMessage::ODOMETRY(o) if o.time_usec == 42))
    );
    let answer = seen
        .iter()
        .find_map(|m| match m {
            MavMessage::TIMESYNC(t) => Some(t),
            _ => None,
        })
        .expect("TIMESYNC answered on the wire");
    assert_eq!(answer.ts1, 123_456_789);
    assert!(answer.tc1 > 0);
    // Nothing between the frames was lost or mangled: one sequence, no gap. The TIMESYNC answer
    // is written by the reader at once and may pass a frame still in the writer's queue: the
    // sequence numbers are consecutive once sorted.
    let first = frames[0].0;
    let mut offsets: Vec<i16> = frames
        .iter()
        .map(|(seq, _)| i16::from(seq.wrapping_sub(first) as i8))
        .collect();
    offsets.sort_unstable();
    for pair in offsets.windows(2) {
        assert_eq!(pair[1], pair[0] + 1, "{offsets:?}");
    }
    let command = link
        .commands
        .recv_timeout(WAIT)
        .expect("the command came through");
    assert_eq!((command.from, command.command.param2), (AUTOPILOT, 2.0));
    assert_eq!(link.counters.timesync_answered.load(Relaxed), 1);
    assert_eq!(link.counters.undecodable.load(Relaxed), 0);
    assert_eq!(link.counters.refused_total(), 0);
    assert_eq!(link.counters.serial_lost.load(Relaxed), 0);
}

#[test]
fn an_unplugged_port_is_counted_reopened_and_streamed_to_again() {
    let dir = Dir::new("unplug");
    let path = dir.0.join("telem");
    let mut port = plug(&path);
    let link = start(&path);
    // A heartbeat every 200 ms until one arrives (those sent before the port is open are lost).
    let heartbeat_until_seen = |link: &Link, master: &mut TTYPort| {
        let deadline = Instant::now() + WAIT;
        loop {
            link.queue(MavMessage::HEARTBEAT(heartbeat(Profile::Onboard, None)));
            let next = Instant::now() + Duration::from_millis(200);
            let got = read_frames(master, |seen| has(seen, HEARTBEAT) || Instant::now() > next);
            if !got.is_empty() || Instant::now() > deadline {
                return got;
            }
        }
    };
    assert!(!heartbeat_until_seen(&link, &mut port.master).is_empty());

    // Unplugged: the path goes, the terminal hangs up.
    std::fs::remove_file(&path).unwrap();
    drop(port);
    let deadline = Instant::now() + WAIT;
    while link.counters.serial_lost.load(Relaxed) == 0 && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(link.counters.serial_lost.load(Relaxed), 1);
    // While it is away, what is sent is lost and counted, never queued up.
    let dropped_before = link.counters.serial_dropped.load(Relaxed);
    for _ in 0..10 {
        link.queue(MavMessage::HEARTBEAT(heartbeat(Profile::Onboard, None)));
    }
    let deadline = Instant::now() + WAIT;
    while link.counters.serial_dropped.load(Relaxed) < dropped_before + 10
        && Instant::now() < deadline
    {
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(
        link.counters.serial_dropped.load(Relaxed),
        dropped_before + 10
    );
    // Let a few attempts to open it fail, then plug it back in.
    std::thread::sleep(Duration::from_millis(400));
    assert_eq!(link.counters.serial_reopened.load(Relaxed), 0);
    let mut port = plug(&path);
    assert!(
        !heartbeat_until_seen(&link, &mut port.master).is_empty(),
        "no stream after the port came back"
    );
    assert_eq!(link.counters.serial_reopened.load(Relaxed), 1);
    assert_eq!(link.counters.serial_lost.load(Relaxed), 1);
}
