//! The network side of the MAVLink output: one thread sends what the navigation loop queued, one
//! thread per socket reads what peers send (TIMESYNC is answered there and then, commands that
//! pass the [`CommandGate`] go to the navigation loop); a serial port has a reader and a writer of
//! its own ([`crate::serial_link`]), fed by the sending thread. The navigation loop never touches
//! a socket or a port: it hands messages over a bounded queue and counts what did not fit, so a
//! slow or absent network or line never holds up the solution. With a signing key, every frame sent is signed and only
//! frames signed with the key are acted on.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

use crossbeam_channel::{Receiver, Sender, TrySendError, bounded};
use mavlink::{MAVLinkMessageRaw, MAVLinkV2MessageRaw, MavlinkReader, MavlinkVersion, Message};

use crate::command_gate::CommandGate;
use crate::dialect::MavMessage;
use crate::endpoint::Endpoint;
use crate::inbound::{Inbound, Origin, READ_POLL};
use crate::serial_link::{self, Frame};
use crate::signing::{self, KEY_BYTES, Verifier};
use crate::speaker::{MAX_FRAME, Speaker};

pub use crate::inbound::InboundCommand;
pub use crate::link_counters::LinkCounters;

/// Commands queued for the navigation loop; a peer flooding commands loses the excess.
const COMMAND_QUEUE: usize = 16;

/// How the link is secured: the signing key and who may send commands.
pub struct LinkSecurity {
    /// The signing key; `None`: frames are sent unsigned and signatures are not checked.
    pub key: Option<[u8; KEY_BYTES]>,
    /// The link id of rins's signatures.
    pub link_id: u8,
    /// Who may send commands.
    pub gate: CommandGate,
}

/// One socket and where its stream goes.
struct Socket {
    socket: UdpSocket,
    /// The peer: fixed for `udpout`, the last sender for `udpin` (none until one spoke).
    peer: Arc<Mutex<Option<SocketAddr>>>,
    listening: bool,
}

/// Every MAVLink 2 message of the common set in `datagram`, in order, handed to `on_message`
/// with its raw frame (for the signature); returns whether the datagram was nothing but such
/// messages (an empty datagram is not). Bytes between, before or after frames, frames with a bad
/// checksum, of another MAVLink version or of an unknown or malformed message make it not so.
pub fn decode_datagram(
    datagram: &[u8],
    mut on_message: impl FnMut(&MAVLinkV2MessageRaw, MavMessage),
) -> bool {
    let mut reader = MavlinkReader::new(datagram);
    let mut framed = 0usize;
    let mut clean = true;
    // The reader skips what is not a valid frame and reports only the end of the bytes: what it
    // skipped shows as bytes not covered by the frames it returned.
    while let Ok(raw) = reader.read_raw_message::<MavMessage>(MavlinkVersion::V2) {
        let MAVLinkMessageRaw::V2(raw) = raw else {
            clean = false;
            continue;
        };
        framed += raw.raw_bytes().len();
        match MavMessage::parse(MavlinkVersion::V2, raw.message_id(), raw.payload()) {
            Ok(msg) => on_message(&raw, msg),
            Err(_) => clean = false,
        }
    }
    clean && framed > 0 && framed == datagram.len()
}

/// The running link: the queue into it, the commands out of it, its counters.
pub struct Link {
    outbound: Option<Sender<MavMessage>>,
    /// Commands from peers, for the navigation loop.
    pub commands: Receiver<InboundCommand>,
    /// What the link counted.
    pub counters: Arc<LinkCounters>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

/// Opens a socket for `endpoint`: `udpout` binds an ephemeral port of the peer's family and sends
/// to the peer, `udpin` binds the given address.
fn open(endpoint: &Endpoint) -> io::Result<Socket> {
    let addr = endpoint.socket_addr()?;
    let (socket, peer, listening) = match endpoint {
        Endpoint::UdpOut { .. } => {
            let any: SocketAddr = if addr.is_ipv4() {
                (std::net::Ipv4Addr::UNSPECIFIED, 0).into()
            } else {
                (std::net::Ipv6Addr::UNSPECIFIED, 0).into()
            };
            (UdpSocket::bind(any)?, Some(addr), false)
        }
        Endpoint::UdpIn { .. } => (UdpSocket::bind(addr)?, None, true),
        // `socket_addr` refused it already: a serial port is no socket.
        Endpoint::Serial { .. } => return Err(io::ErrorKind::InvalidInput.into()),
    };
    socket.set_read_timeout(Some(READ_POLL))?;
    Ok(Socket {
        socket,
        peer: Arc::new(Mutex::new(peer)),
        listening,
    })
}

/// The peer of `socket` now.
fn peer_of(peer: &Mutex<Option<SocketAddr>>) -> Option<SocketAddr> {
    *peer.lock().unwrap_or_else(PoisonError::into_inner)
}

impl Link {
    /// Opens every endpoint and starts the threads; rins speaks as `(system, component)`, signs
    /// and admits commands as `security` says. An endpoint that cannot be opened is an error
    /// naming it.
    pub fn start(
        endpoints: &[Endpoint],
        speaker: (u8, u8),
        queue_capacity: usize,
        security: LinkSecurity,
    ) -> io::Result<Self> {
        let mut sockets = Vec::with_capacity(endpoints.len());
        let mut ports = Vec::new();
        for e in endpoints {
            if let Endpoint::Serial { path, baud } = e {
                // Opened by its reader, which waits for a port that is not there yet.
                ports.push((path.clone(), *baud));
                continue;
            }
            let s = open(e).map_err(|err| io::Error::new(err.kind(), format!("{e}: {err}")))?;
            sockets.push(s);
        }
        let speaker = Arc::new(Speaker::new(
            speaker.0,
            speaker.1,
            security
                .key
                .map(|key| signing::outgoing(key, security.link_id)),
        ));
        // One verifier for every socket: a frame replayed onto another endpoint is still a replay.
        let verifier = security
            .key
            .map(|key| Arc::new(Mutex::new(Verifier::new(key))));
        let gate = Arc::new(security.gate);
        let counters = Arc::new(LinkCounters::default());
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = bounded::<MavMessage>(queue_capacity);
        let (cmd_tx, cmd_rx) = bounded::<InboundCommand>(COMMAND_QUEUE);
        let inbound = Inbound {
            speaker: Arc::clone(&speaker),
            counters: Arc::clone(&counters),
            commands: cmd_tx,
            verifier,
            gate,
        };
        let mut threads = Vec::new();
        for s in &sockets {
            let reader = ReaderThread {
                socket: s.socket.try_clone()?,
                peer: Arc::clone(&s.peer),
                listening: s.listening,
                stop: Arc::clone(&stop),
                inbound: inbound.clone(),
            };
            threads.push(
                std::thread::Builder::new()
                    .name("mavlink-rx".into())
                    .spawn(move || reader.run())?,
            );
        }
        let mut port_queues = Vec::with_capacity(ports.len());
        for (path, baud) in ports {
            // Frames wait here for the port's writer, so that a slow line holds up neither the
            // sockets nor the navigation loop.
            let (frame_tx, frame_rx) = bounded::<Frame>(queue_capacity);
            port_queues.push(frame_tx);
            threads.extend(serial_link::start(
                path,
                baud,
                frame_rx,
                inbound.clone(),
                Arc::clone(&stop),
            )?);
        }
        let sender_counters = Arc::clone(&counters);
        threads.push(
            std::thread::Builder::new()
                .name("mavlink-tx".into())
                .spawn(move || {
                    send_loop(&rx, &sockets, &port_queues, &speaker, &sender_counters);
                })?,
        );
        Ok(Self {
            outbound: Some(tx),
            commands: cmd_rx,
            counters,
            stop,
            threads,
        })
    }

    /// Hands `msg` to the network thread without waiting; a full queue drops it and counts it.
    pub fn queue(&self, msg: MavMessage) {
        let Some(tx) = &self.outbound else { return };
        match tx.try_send(msg) {
            Ok(()) => self.counters.queued.fetch_add(1, Ordering::Relaxed),
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => {
                self.counters.dropped.fetch_add(1, Ordering::Relaxed)
            }
        };
    }
}

impl Drop for Link {
    fn drop(&mut self) {
        // Closing the queue ends the sender once it has sent what was queued; the readers see
        // the flag within one poll.
        self.outbound = None;
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}

/// Sends every queued message to every endpoint that has a peer and hands it to every serial
/// port's writer, until the queue closes.
fn send_loop(
    rx: &Receiver<MavMessage>,
    sockets: &[Socket],
    ports: &[Sender<Frame>],
    speaker: &Speaker,
    counters: &LinkCounters,
) {
    let mut buf = [0u8; MAX_FRAME];
    for msg in rx {
        let Some(len) = speaker.frame(&msg, &mut buf) else {
            continue;
        };
        for port in ports {
            if port.try_send(Frame::new(&buf[..len])).is_err() {
                counters.serial_dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
        for s in sockets {
            let Some(peer) = peer_of(&s.peer) else {
                continue;
            };
            match s.socket.send_to(&buf[..len], peer) {
                Ok(_) => counters.sent.fetch_add(1, Ordering::Relaxed),
                Err(_) => counters.send_errors.fetch_add(1, Ordering::Relaxed),
            };
        }
    }
}

/// Reads one socket: answers TIMESYNC, forwards admitted commands, learns a listening socket's
/// peer.
struct ReaderThread {
    socket: UdpSocket,
    peer: Arc<Mutex<Option<SocketAddr>>>,
    listening: bool,
    stop: Arc<AtomicBool>,
    inbound: Inbound,
}

impl ReaderThread {
    fn run(self) {
        let mut datagram = [0u8; 2048];
        let mut frame = [0u8; MAX_FRAME];
        while !self.stop.load(Ordering::Relaxed) {
            let (n, from) = match self.socket.recv_from(&mut datagram) {
                Ok(r) => r,
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut
                    ) =>
                {
                    continue;
                }
                // An ICMP "port unreachable" from a peer not listening yet: try again.
                Err(_) => {
                    std::thread::sleep(READ_POLL);
                    continue;
                }
            };
            // A datagram may carry several frames.
            let mut authentic = false;
            let clean = decode_datagram(&datagram[..n], |raw, msg| {
                let reply = |bytes: &[u8]| self.socket.send_to(bytes, from).is_ok();
                authentic |=
                    self.inbound
                        .on_message(raw, msg, Origin::Peer(from), &mut frame, reply);
            });
            if !clean {
                self.inbound
                    .counters
                    .undecodable
                    .fetch_add(1, Ordering::Relaxed);
            }
            // The stream follows only a peer that spoke MAVLink (signed with the key, when one
            // is set): a stray or forged datagram cannot divert it.
            if self.listening && authentic {
                *self.peer.lock().unwrap_or_else(PoisonError::into_inner) = Some(from);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::COMMAND_LONG_DATA;
    use crate::signing::SignatureCheck;
    use mavlink::{MavHeader, SigningData};

    /// A signed COMMAND_LONG frame.
    fn signed_command(signer: &SigningData) -> Vec<u8> {
        let header = MavHeader {
            system_id: 255,
            component_id: 190,
            sequence: 3,
        };
        let mut bytes = Vec::new();
        mavlink::write_v2_msg_signed(
            &mut bytes,
            header,
            &MavMessage::COMMAND_LONG(COMMAND_LONG_DATA::default()),
            Some(signer),
        )
        .unwrap();
        bytes
    }

    #[test]
    fn mangled_datagrams_never_panic_and_never_pass_as_signed() {
        let key = [3u8; KEY_BYTES];
        let signer = signing::outgoing(key, 0);
        let mut verifier = Verifier::new(key);
        let now = signing::timestamp_now();
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut valid = 0;
        for _ in 0..20_000 {
            let original = signed_command(&signer);
            let mut d = original.clone();
            // One to four changed bytes, then maybe cut or lengthened.
            for _ in 0..=(next() % 4) {
                let i = (next() as usize) % d.len();
                d[i] ^= (next() as u8) | 1;
            }
            match next() % 3 {
                0 => d.truncate((next() as usize) % (d.len() + 1)),
                // Up to the largest datagram read, with frame starts among the bytes.
                1 => d.extend((0..next() % 2000).map(|_| match next() % 8 {
                    0 => 0xfd,
                    _ => next() as u8,
                })),
                _ => {}
            }
            // Two changes of one byte may cancel out: only a frame that did change counts.
            let changed = !d.starts_with(&original);
            decode_datagram(&d, |raw, _| {
                if verifier.check(raw, now) == SignatureCheck::Valid && changed {
                    valid += 1;
                }
            });
        }
        // Whatever byte changed — one the checksum covers, the signature's or its timestamp's —
        // the frame never passes as signed with the key.
        assert_eq!(valid, 0);
        // Nothing at all is not a message either.
        assert!(!decode_datagram(&[], |_, _| {}));
    }
}
