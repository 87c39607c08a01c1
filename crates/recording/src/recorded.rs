//! What reading a recording yields: each readable message with its topic, times and payload
//! bytes, what was skipped and why, and a whole recording read into memory.

use std::sync::Arc;

use crate::cdr::Recordable;
use crate::error::DecodeError;
use crate::schema::StructLayout;

/// Skipped messages described one by one, at most; beyond, they are only counted.
pub const MAX_SKIP_DETAILS: usize = 100;

/// One recorded sample.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordedMessage {
    /// Its topic.
    pub topic: Arc<str>,
    /// The layout of its payload type.
    pub layout: &'static StructLayout,
    /// When the recorder received it, ns (the recorder's clock).
    pub log_time_ns: u64,
    /// When it was published, ns.
    pub publish_time_ns: u64,
    /// Its sequence number in its channel.
    pub sequence: u32,
    /// The payload's bytes (without the CDR header), `layout.size` of them.
    pub payload: Vec<u8>,
}

impl RecordedMessage {
    /// The payload as a `T`; an error when the message is of another type.
    pub fn decode<T: Recordable>(&self) -> Result<T, DecodeError> {
        decode(self)
    }
}

/// The payload of `message` as a `T`; an error when the message is of another type or length.
pub fn decode<T: Recordable>(message: &RecordedMessage) -> Result<T, DecodeError> {
    let expected = T::layout();
    if !core::ptr::eq(message.layout, expected) {
        return Err(DecodeError::WrongType {
            topic: message.topic.to_string(),
            expected: expected.type_name,
            found: message.layout.type_name,
        });
    }
    T::from_bytes(&message.payload).ok_or_else(|| DecodeError::WrongLength {
        topic: message.topic.to_string(),
        expected_type: expected.type_name,
        expected: expected.size,
        found: message.payload.len(),
    })
}

/// Why a message was skipped.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum SkipReason {
    /// Its length is not its channel's payload size (plus the CDR header).
    WrongLength {
        /// Payload size plus the 4-byte CDR header.
        expected: usize,
        /// The message's length.
        found: usize,
    },
    /// It does not start with the little-endian CDR header.
    NotCdr,
    /// Its `version` field is not this build's payload version.
    WrongVersion {
        /// The version found.
        found: u16,
    },
    /// Its channel was never defined (its definition was in a damaged chunk, say).
    UnknownChannel {
        /// The channel id the message names.
        channel: u16,
    },
}

/// A message that was skipped, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    /// Its topic (`channel N` for a channel never defined).
    pub topic: String,
    /// Its log time, ns.
    pub log_time_ns: u64,
    /// Why.
    pub reason: SkipReason,
}

/// A whole recording, read into memory.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Every readable message, in file order.
    pub messages: Vec<RecordedMessage>,
    /// Messages skipped (see [`Messages::skipped_count`](crate::Messages::skipped_count)).
    pub skipped_count: u64,
    /// The first [`MAX_SKIP_DETAILS`] skipped messages.
    pub skipped: Vec<Skipped>,
    /// Chunks skipped as damaged (see
    /// [`Messages::damaged_chunk_count`](crate::Messages::damaged_chunk_count)).
    pub damaged_chunk_count: u64,
    /// The first [`MAX_SKIP_DETAILS`] damaged chunks.
    pub damaged_chunks: Vec<DamagedChunk>,
    /// Where reading stopped early and why (a cut-off file), `None` for a complete file.
    pub damage: Option<String>,
}

/// A chunk (or a record outside any chunk) skipped as damaged.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DamagedChunk {
    /// Where it starts in the file, bytes.
    pub offset: u64,
    /// What is wrong with it.
    pub reason: String,
}
