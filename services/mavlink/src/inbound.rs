//! What every reader, of a UDP socket or of a serial port, does with a message it received:
//! TIMESYNC is answered there and then, commands that pass the [`CommandGate`] go to the
//! navigation loop, and what is refused is counted.

use std::fmt;
use std::net::SocketAddr;
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use crossbeam_channel::Sender;
use mavlink::{MAVLinkV2MessageRaw, MavHeader};

use crate::command_gate::{CommandGate, Refusal};
use crate::dialect::{COMMAND_LONG_DATA, MavMessage};
use crate::link_counters::LinkCounters;
use crate::signing::{self, SignatureCheck, Verifier};
use crate::speaker::{MAX_FRAME, Speaker};
use crate::timesync;

/// How often a reader looks at the stop flag while nothing arrives.
pub(crate) const READ_POLL: Duration = Duration::from_millis(100);

/// A command from a peer, with who sent it.
#[derive(Debug, Clone)]
pub struct InboundCommand {
    /// The sender's system and component.
    pub from: (u8, u8),
    /// The command.
    pub command: COMMAND_LONG_DATA,
}

/// Where an inbound message came from.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Origin<'a> {
    /// A UDP peer.
    Peer(SocketAddr),
    /// A serial port, by its device path.
    Port(&'a str),
}

impl fmt::Display for Origin<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Peer(addr) => write!(f, "{addr}"),
            Self::Port(path) => write!(f, "{path}"),
        }
    }
}

/// What every reader, of a socket or of a serial port, acts on messages with.
#[derive(Clone)]
pub(crate) struct Inbound {
    pub(crate) speaker: Arc<Speaker>,
    pub(crate) counters: Arc<LinkCounters>,
    pub(crate) commands: Sender<InboundCommand>,
    /// The signature check, when a key is set; one for every endpoint: a frame replayed onto
    /// another endpoint is still a replay.
    pub(crate) verifier: Option<Arc<Mutex<Verifier>>>,
    pub(crate) gate: Arc<CommandGate>,
}

impl Inbound {
    /// What `raw`'s signature shows.
    fn signature(&self, raw: &MAVLinkV2MessageRaw) -> SignatureCheck {
        match &self.verifier {
            Some(v) => v
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .check(raw, signing::timestamp_now()),
            None => SignatureCheck::NotChecked,
        }
    }

    /// Acts on one message from `from`; `reply` sends a frame back there and says whether it
    /// went. Returns whether the message is authentic (signed with the key, or no key set).
    pub(crate) fn on_message(
        &self,
        raw: &MAVLinkV2MessageRaw,
        msg: MavMessage,
        from: Origin<'_>,
        frame: &mut [u8; MAX_FRAME],
        reply: impl FnOnce(&[u8]) -> bool,
    ) -> bool {
        let signature = self.signature(raw);
        let authentic = matches!(
            signature,
            SignatureCheck::Valid | SignatureCheck::NotChecked
        );
        let header = MavHeader {
            system_id: raw.system_id(),
            component_id: raw.component_id(),
            sequence: raw.sequence(),
        };
        let sender = (header.system_id, header.component_id);
        match msg {
            MavMessage::TIMESYNC(_) if !authentic => {
                let refusal = match signature {
                    SignatureCheck::BadSignature => Refusal::BadSignature,
                    SignatureCheck::Replayed => Refusal::Replayed,
                    _ => Refusal::Unsigned,
                };
                self.counters.refused(refusal, sender, from);
            }
            MavMessage::TIMESYNC(request) => {
                let now = rins_runtime::clock::monotonic_ns();
                if let Some(mut answer) = timesync::answer(&request, now, self.speaker.system()) {
                    answer.target_system = u8::try_from(header.system_id).unwrap_or(0);
                    answer.target_component = header.component_id;
                    if let Some(len) = self.speaker.frame(&MavMessage::TIMESYNC(answer), frame)
                        && reply(&frame[..len])
                    {
                        self.counters
                            .timesync_answered
                            .fetch_add(1, Ordering::Relaxed);
                    }
                }
            }
            MavMessage::COMMAND_LONG(command) => {
                let admitted = match from {
                    Origin::Peer(addr) => self.gate.admit(signature, sender, addr),
                    Origin::Port(_) => self.gate.admit_wired(signature, sender),
                };
                if let Err(refusal) = admitted {
                    self.counters.refused(refusal, sender, from);
                    return authentic;
                }
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
        authentic
    }
}
