//! The link over real UDP on the loopback: with a signing key, what rins sends is signed with it,
//! and only commands signed with it, from an allowed sender and address, reach the navigation
//! loop; every refusal and every undecodable datagram is counted exactly.
//!
//! Each check ends with a "fence": a command that is admitted, sent after the datagrams under
//! test from the same socket. The reader handles a socket's datagrams in order, so once the fence
//! comes out of the link every datagram before it has been handled and the counters are final;
//! a datagram lost on the way would show as a count too low, never as a wait.

use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::Ordering::Relaxed;
use std::time::Duration;

use mavlink::{MAVLinkV2MessageRaw, MavHeader, SigningData};
use rins_mavlink::command_gate::CommandGate;
use rins_mavlink::config::{CommandSource, MavlinkConfig};
use rins_mavlink::dialect::{COMMAND_LONG_DATA, HEARTBEAT_DATA, MavCmd, MavMessage, TIMESYNC_DATA};
use rins_mavlink::endpoint::Endpoint;
use rins_mavlink::link::{Link, LinkSecurity};
use rins_mavlink::signing::{self, SignatureCheck, Verifier};

const KEY: [u8; 32] = *b"rins-test-key-0123456789abcdef!!";
/// The ground station commands are taken from.
const GCS: (u8, u8) = (255, 190);
const WAIT: Duration = Duration::from_secs(5);

/// A link streaming to a client socket on 127.0.0.1, taking commands from [`GCS`] at 127.0.0.1
/// only; the client and the link's own address, learned from the first (signed) frame it sent.
struct Rig {
    link: Link,
    client: UdpSocket,
    link_addr: SocketAddr,
}

fn rig(key: Option<[u8; 32]>) -> Rig {
    let client = UdpSocket::bind("127.0.0.1:0").unwrap();
    client.set_read_timeout(Some(WAIT)).unwrap();
    let config = MavlinkConfig {
        accept_commands: true,
        signing_key_file: key.map(|_| "/unused".into()),
        allow_unsigned_commands: key.is_none(),
        command_sources: vec![CommandSource {
            system: GCS.0,
            component: Some(GCS.1),
        }],
        command_addresses: vec!["127.0.0.1".into()],
        ..MavlinkConfig::default()
    };
    assert_eq!(config.validate(), Ok(()));
    let endpoint = Endpoint::UdpOut {
        host: "127.0.0.1".into(),
        port: client.local_addr().unwrap().port(),
    };
    let link = Link::start(
        &[endpoint],
        (1, 197),
        64,
        LinkSecurity {
            key,
            link_id: 5,
            gate: CommandGate::new(&config, key.is_some()),
        },
    )
    .unwrap();
    link.queue(MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()));
    let mut buf = [0u8; 512];
    let (n, link_addr) = client.recv_from(&mut buf).expect("the link's first frame");
    let raw = raw_of(&buf[..n]);
    let expected = if key.is_some() {
        SignatureCheck::Valid
    } else {
        SignatureCheck::Unsigned
    };
    assert_eq!(
        Verifier::new(KEY).check(&raw, signing::timestamp_now()),
        expected
    );
    if key.is_some() {
        assert_eq!(raw.signature_link_id(), 5);
    }
    Rig {
        link,
        client,
        link_addr,
    }
}

fn raw_of(bytes: &[u8]) -> MAVLinkV2MessageRaw {
    let mut raw = MAVLinkV2MessageRaw::new();
    raw.as_mut_slice()[..bytes.len()].copy_from_slice(bytes);
    raw
}

/// `msg` from `(system, component)` as one frame, signed by `signer` (or not).
fn frame(msg: &MavMessage, from: (u8, u8), signer: Option<&SigningData>) -> Vec<u8> {
    let header = MavHeader {
        system_id: u32::from(from.0),
        component_id: from.1,
        sequence: 0,
    };
    let mut bytes = Vec::new();
    mavlink::write_v2_msg_signed(&mut bytes, header, msg, signer).unwrap();
    bytes
}

/// A re-admission of accel `channel`, addressed to rins.
fn readmit(channel: f32) -> MavMessage {
    MavMessage::COMMAND_LONG(COMMAND_LONG_DATA {
        target_system: 1,
        target_component: 197,
        command: MavCmd::MAV_CMD_USER_1,
        param1: 1.0,
        param2: channel,
        ..COMMAND_LONG_DATA::default()
    })
}

impl Rig {
    fn send(&self, bytes: &[u8]) {
        self.client.send_to(bytes, self.link_addr).unwrap();
    }

    /// Sends an admitted command marked by `channel` and waits for it; every command that came out
    /// of the link before it is returned (by their `param2`).
    fn fence(&self, signer: Option<&SigningData>, channel: f32) -> Vec<f32> {
        self.send(&frame(&readmit(channel), GCS, signer));
        let mut before = Vec::new();
        loop {
            let c = self
                .link
                .commands
                .recv_timeout(WAIT)
                .expect("the fence command comes through");
            if c.command.param2 == channel {
                assert_eq!(c.from, GCS);
                return before;
            }
            before.push(c.command.param2);
        }
    }
}

#[test]
fn only_commands_signed_with_the_key_from_allowed_senders_pass() {
    let r = rig(Some(KEY));
    let signer = signing::outgoing(KEY, 0);
    let c = &r.link.counters;

    // Correctly signed, from the allowed sender and address: through.
    r.send(&frame(&readmit(1.0), GCS, Some(&signer)));
    let got = r
        .link
        .commands
        .recv_timeout(WAIT)
        .expect("a signed command");
    assert_eq!((got.from, got.command.param2), (GCS, 1.0));

    // Unsigned.
    r.send(&frame(&readmit(2.0), GCS, None));
    // The signed flag with a garbage signature (the last 6 bytes of a signed frame).
    let mut garbage = frame(&readmit(3.0), GCS, Some(&signer));
    let len = garbage.len();
    garbage[len - 6..].copy_from_slice(&[0xa5; 6]);
    r.send(&garbage);
    // Signed with another key.
    let stranger = signing::outgoing([9; 32], 0);
    r.send(&frame(&readmit(4.0), GCS, Some(&stranger)));
    // A correctly signed frame sent again.
    let replayed = frame(&readmit(5.0), GCS, Some(&signer));
    r.send(&replayed);
    r.send(&replayed);
    // Signed, from a system and from a component not allowed.
    r.send(&frame(&readmit(6.0), (254, 190), Some(&signer)));
    r.send(&frame(&readmit(7.0), (255, 1), Some(&signer)));
    // An unsigned TIMESYNC request is not answered either.
    let timesync = MavMessage::TIMESYNC(TIMESYNC_DATA {
        tc1: 0,
        ts1: 42,
        ..TIMESYNC_DATA::default()
    });
    r.send(&frame(&timesync, GCS, None));

    assert_eq!(r.fence(Some(&signer), 100.0), vec![5.0]);
    assert_eq!(c.unsigned_refused.load(Relaxed), 2);
    assert_eq!(c.bad_signature_refused.load(Relaxed), 2);
    assert_eq!(c.replay_refused.load(Relaxed), 1);
    assert_eq!(c.sender_refused.load(Relaxed), 2);
    assert_eq!(c.address_refused.load(Relaxed), 0);
    assert_eq!(c.timesync_answered.load(Relaxed), 0);
    assert_eq!(c.undecodable.load(Relaxed), 0);

    // A signed TIMESYNC request is answered, signed.
    r.send(&frame(&timesync, GCS, Some(&signer)));
    let mut buf = [0u8; 512];
    let answer = loop {
        let (n, _) = r.client.recv_from(&mut buf).expect("a TIMESYNC answer");
        let raw = raw_of(&buf[..n]);
        if raw.message_id() == 111 {
            break raw;
        }
    };
    assert_eq!(
        Verifier::new(KEY).check(&answer, signing::timestamp_now()),
        SignatureCheck::Valid
    );
    // The link counts an answer once its send returned, which may be after the answer arrived.
    let counted = std::time::Instant::now();
    while c.timesync_answered.load(Relaxed) == 0 && counted.elapsed().as_secs_f64() < 2.0 {
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    assert_eq!(c.timesync_answered.load(Relaxed), 1);
}

#[test]
fn signed_commands_from_an_address_not_allowed_are_refused() {
    let r = rig(Some(KEY));
    let signer = signing::outgoing(KEY, 0);
    // Another address on the loopback: the right key and sender, the wrong place.
    let elsewhere = UdpSocket::bind("127.0.0.2:0").unwrap();
    for channel in [1.0, 2.0, 3.0] {
        elsewhere
            .send_to(&frame(&readmit(channel), GCS, Some(&signer)), r.link_addr)
            .unwrap();
    }
    // The fence comes from the allowed address; the other socket's datagrams may still be on the
    // way, so wait for them to be counted before it.
    let deadline = std::time::Instant::now() + WAIT;
    while r.link.counters.address_refused.load(Relaxed) < 3 && std::time::Instant::now() < deadline
    {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert_eq!(r.fence(Some(&signer), 100.0), Vec::<f32>::new());
    assert_eq!(r.link.counters.address_refused.load(Relaxed), 3);
    assert_eq!(r.link.counters.refused_total(), 3);
}

#[test]
fn every_undecodable_datagram_is_counted_once() {
    let r = rig(None);
    let valid = frame(&MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()), GCS, None);
    let mut sent = 0u64;
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for i in 0..500u32 {
        // Random bytes, a frame cut short, a frame with bad bytes after it, a frame with a wrong
        // checksum, a MAVLink 1 frame, one byte.
        let datagram: Vec<u8> = match i % 6 {
            0 => (0..(1 + i % 300))
                .map(|_| {
                    seed ^= seed << 13;
                    seed ^= seed >> 7;
                    seed ^= seed << 17;
                    seed as u8
                })
                .collect(),
            1 => valid[..valid.len() - 3].to_vec(),
            2 => [valid.as_slice(), &[0xfd, 1, 2]].concat(),
            3 => {
                let mut v = valid.clone();
                v[12] ^= 0xff;
                v
            }
            4 => {
                let mut v = Vec::new();
                mavlink::write_v1_msg(
                    &mut v,
                    MavHeader::default(),
                    &MavMessage::HEARTBEAT(HEARTBEAT_DATA::default()),
                )
                .unwrap();
                v
            }
            _ => vec![0xfd],
        };
        r.send(&datagram);
        sent += 1;
        // Paced, so that the loopback's receive buffer never overflows.
        std::thread::sleep(Duration::from_micros(300));
    }
    // Two whole frames in one datagram are not undecodable, and both are taken; so is a frame in
    // front of bad bytes.
    let command = frame(&readmit(1.0), GCS, None);
    r.send(&[command.as_slice(), command.as_slice()].concat());
    r.send(&[command.as_slice(), &[0x55]].concat());
    assert_eq!(r.fence(None, 100.0), vec![1.0, 1.0, 1.0]);
    assert_eq!(r.link.counters.undecodable.load(Relaxed), sent + 1);
}
