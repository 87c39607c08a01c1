//! What the MAVLink link counted since start: messages queued, sent and dropped, frames that were
//! not MAVLink, the serial ports' losses, and the commands refused, by why.

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::command_gate::Refusal;

/// What the link counted since start.
#[derive(Debug, Default)]
pub struct LinkCounters {
    /// Messages handed to the network thread.
    pub queued: AtomicU64,
    /// Messages dropped because the queue to the network thread was full.
    pub dropped: AtomicU64,
    /// Datagrams sent (one per message and endpoint with a peer), and frames written to serial
    /// ports.
    pub sent: AtomicU64,
    /// Sends the system refused (unreachable peer, no route).
    pub send_errors: AtomicU64,
    /// Datagrams received that were not, in whole, MAVLink 2 messages of the common set: one per
    /// such datagram, whatever it held besides; on a serial port, frames with a valid checksum of
    /// a message the common set does not know or cannot decode.
    pub undecodable: AtomicU64,
    /// Frames not written to a serial port: the port was away (unplugged, not yet reopened), its
    /// queue was full (a line too slow for the configured rates) or the write failed.
    pub serial_dropped: AtomicU64,
    /// Times a serial port was lost (unplugged, hung up, failed reading).
    pub serial_lost: AtomicU64,
    /// Times a serial port was opened again after it was lost or could not be opened.
    pub serial_reopened: AtomicU64,
    /// TIMESYNC requests answered.
    pub timesync_answered: AtomicU64,
    /// Commands dropped because the navigation loop had not taken the earlier ones.
    pub commands_dropped: AtomicU64,
    /// Commands and TIMESYNC requests refused because they were not signed (a key is set, or
    /// commands are accepted without one and unsigned ones are not allowed).
    pub unsigned_refused: AtomicU64,
    /// Commands and TIMESYNC requests refused because their signature was not made with the key.
    pub bad_signature_refused: AtomicU64,
    /// Commands and TIMESYNC requests refused because, signed with the key, they were not newer
    /// than their stream's last frame (a replay).
    pub replay_refused: AtomicU64,
    /// Commands refused because their sender is not in `command_sources`.
    pub sender_refused: AtomicU64,
    /// Commands refused because their address is not in `command_addresses`.
    pub address_refused: AtomicU64,
    /// COMMAND_ACKs not sent because they exceeded `command_ack_rate_hz`.
    pub acks_dropped: AtomicU64,
}

impl LinkCounters {
    /// Counts `refusal`; the first of each kind is logged, with who sent it, so that a link set up
    /// wrongly (a ground station not signing) shows at once without a flood of log lines.
    pub(crate) fn refused(&self, refusal: Refusal, sender: (u32, u8), from: impl fmt::Display) {
        let (counter, why) = match refusal {
            Refusal::Unsigned => (&self.unsigned_refused, "not signed"),
            Refusal::BadSignature => (&self.bad_signature_refused, "not signed with the key"),
            Refusal::Replayed => (&self.replay_refused, "a replayed signature"),
            Refusal::Sender => (&self.sender_refused, "sender not in command_sources"),
            Refusal::Address => (&self.address_refused, "address not in command_addresses"),
        };
        if counter.fetch_add(1, Ordering::Relaxed) == 0 {
            tracing::warn!(
                %from,
                system = sender.0,
                component = sender.1,
                "MAVLink message refused: {why} (further ones are only counted)"
            );
        }
    }

    /// The refusals of every kind.
    pub fn refused_total(&self) -> u64 {
        [
            &self.unsigned_refused,
            &self.bad_signature_refused,
            &self.replay_refused,
            &self.sender_refused,
            &self.address_refused,
        ]
        .iter()
        .map(|c| c.load(Ordering::Relaxed))
        .sum()
    }
}
