//! The network side of the MAVLink output: one thread sends what the navigation loop queued, one
//! thread per socket reads what peers send (TIMESYNC is answered there and then, commands go to
//! the navigation loop). The navigation loop never touches a socket: it hands messages over a
//! bounded queue and counts what did not fit, so a slow or absent network never holds up the
//! solution.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicU8, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use crossbeam_channel::{Receiver, Sender, TrySendError, bounded};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};

use crate::dialect::{COMMAND_LONG_DATA, MavMessage};
use crate::endpoint::Endpoint;
use crate::timesync;

/// Largest MAVLink 2 frame (header 10, payload 255, checksum 2, signature 13).
const MAX_FRAME: usize = 280;
/// How often a reader looks at the stop flag while nothing arrives.
const READ_POLL: Duration = Duration::from_millis(100);
/// Commands queued for the navigation loop; a peer flooding commands loses the excess.
const COMMAND_QUEUE: usize = 16;

/// A command from a peer, with who sent it.
#[derive(Debug, Clone)]
pub struct InboundCommand {
    /// The sender's system and component.
    pub from: (u8, u8),
    /// The command.
    pub command: COMMAND_LONG_DATA,
}

/// What the link counted since start.
#[derive(Debug, Default)]
pub struct LinkCounters {
    /// Messages handed to the network thread.
    pub queued: AtomicU64,
    /// Messages dropped because the queue to the network thread was full.
    pub dropped: AtomicU64,
    /// Datagrams sent (one per message and endpoint with a peer).
    pub sent: AtomicU64,
    /// Sends the system refused (unreachable peer, no route).
    pub send_errors: AtomicU64,
    /// Datagrams received that were not MAVLink 2 messages of the common set.
    pub undecodable: AtomicU64,
    /// TIMESYNC requests answered.
    pub timesync_answered: AtomicU64,
    /// Commands dropped because the navigation loop had not taken the earlier ones.
    pub commands_dropped: AtomicU64,
}

/// One socket and where its stream goes.
struct Socket {
    socket: UdpSocket,
    /// The peer: fixed for `udpout`, the last sender for `udpin` (none until one spoke).
    peer: Arc<Mutex<Option<SocketAddr>>>,
    listening: bool,
}

/// Who rins speaks as, and the sequence number every frame it sends shares.
struct Speaker {
    system: u8,
    component: u8,
    sequence: AtomicU8,
}

impl Speaker {
    /// `msg` framed as MAVLink 2 into `buf`; the frame's length.
    fn frame(&self, msg: &MavMessage, buf: &mut [u8; MAX_FRAME]) -> Option<usize> {
        let header = MavHeader {
            system_id: u32::from(self.system),
            component_id: self.component,
            sequence: self.sequence.fetch_add(1, Ordering::Relaxed),
        };
        let mut cursor = io::Cursor::new(&mut buf[..]);
        mavlink::write_v2_msg(&mut cursor, header, msg).ok()?;
        Some(cursor.position() as usize)
    }
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
    /// Opens every endpoint and starts the threads; rins speaks as `(system, component)`. An
    /// endpoint that cannot be opened is an error naming it.
    pub fn start(
        endpoints: &[Endpoint],
        speaker: (u8, u8),
        queue_capacity: usize,
    ) -> io::Result<Self> {
        let mut sockets = Vec::with_capacity(endpoints.len());
        for e in endpoints {
            let s = open(e).map_err(|err| io::Error::new(err.kind(), format!("{e}: {err}")))?;
            sockets.push(s);
        }
        let speaker = Arc::new(Speaker {
            system: speaker.0,
            component: speaker.1,
            sequence: AtomicU8::new(0),
        });
        let counters = Arc::new(LinkCounters::default());
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = bounded::<MavMessage>(queue_capacity);
        let (cmd_tx, cmd_rx) = bounded::<InboundCommand>(COMMAND_QUEUE);
        let mut threads = Vec::new();
        for s in &sockets {
            let reader = ReaderThread {
                socket: s.socket.try_clone()?,
                peer: Arc::clone(&s.peer),
                listening: s.listening,
                speaker: Arc::clone(&speaker),
                counters: Arc::clone(&counters),
                commands: cmd_tx.clone(),
                stop: Arc::clone(&stop),
            };
            threads.push(
                std::thread::Builder::new()
                    .name("mavlink-rx".into())
                    .spawn(move || reader.run())?,
            );
        }
        let sender_counters = Arc::clone(&counters);
        threads.push(
            std::thread::Builder::new()
                .name("mavlink-tx".into())
                .spawn(move || send_loop(&rx, &sockets, &speaker, &sender_counters))?,
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

/// Sends every queued message to every endpoint that has a peer, until the queue closes.
fn send_loop(
    rx: &Receiver<MavMessage>,
    sockets: &[Socket],
    speaker: &Speaker,
    counters: &LinkCounters,
) {
    let mut buf = [0u8; MAX_FRAME];
    for msg in rx {
        let Some(len) = speaker.frame(&msg, &mut buf) else {
            continue;
        };
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

/// Reads one socket: answers TIMESYNC, forwards commands, learns a listening socket's peer.
struct ReaderThread {
    socket: UdpSocket,
    peer: Arc<Mutex<Option<SocketAddr>>>,
    listening: bool,
    speaker: Arc<Speaker>,
    counters: Arc<LinkCounters>,
    commands: Sender<InboundCommand>,
    stop: Arc<AtomicBool>,
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
            if self.listening {
                *self.peer.lock().unwrap_or_else(PoisonError::into_inner) = Some(from);
            }
            // A datagram may carry several frames.
            let mut reader = MavlinkReader::new(&datagram[..n]);
            loop {
                match reader.read_message::<MavMessage>(MavlinkVersion::V2) {
                    Ok((header, msg)) => self.on_message(header, msg, from, &mut frame),
                    Err(mavlink::error::MessageReadError::Io(_)) => break,
                    Err(_) => {
                        self.counters.undecodable.fetch_add(1, Ordering::Relaxed);
                        break;
                    }
                }
            }
        }
    }

    fn on_message(
        &self,
        header: MavHeader,
        msg: MavMessage,
        from: SocketAddr,
        frame: &mut [u8; MAX_FRAME],
    ) {
        match msg {
            MavMessage::TIMESYNC(request) => {
                let now = rins_runtime::clock::monotonic_ns();
                if let Some(mut answer) = timesync::answer(&request, now, self.speaker.system) {
                    answer.target_system = u8::try_from(header.system_id).unwrap_or(0);
                    answer.target_component = header.component_id;
                    if let Some(len) = self.speaker.frame(&MavMessage::TIMESYNC(answer), frame)
                        && self.socket.send_to(&frame[..len], from).is_ok()
                    {
                        self.counters
                            .timesync_answered
                            .fetch_add(1, Ordering::Relaxed);
                    }
                }
            }
            MavMessage::COMMAND_LONG(command) => {
                let inbound = InboundCommand {
                    // A system id beyond 255 (a MAVLink 2 extension) cannot be answered in kind.
                    from: (
                        u8::try_from(header.system_id).unwrap_or(0),
                        header.component_id,
                    ),
                    command,
                };
                if self.commands.try_send(inbound).is_err() {
                    self.counters
                        .commands_dropped
                        .fetch_add(1, Ordering::Relaxed);
                }
            }
            _ => {}
        }
    }
}
