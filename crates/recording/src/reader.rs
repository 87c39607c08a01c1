//! Reading a recording back: every message with its topic and times, its payload bytes checked
//! against this build's layouts.
//!
//! A channel recorded with another payload version or an unknown payload type stops the reading
//! with an error naming the topic: its bytes would be misread. Damage that only costs some
//! messages does not: a message of the wrong length (or without the CDR header, or with another
//! version in its `version` field) is skipped and counted with the reason, and a file that ends
//! early (the recorder was killed before it finished the file) yields every message of its
//! complete chunks, then reports where reading stopped in [`Messages::damage`]. The messages of
//! the chunk being written when the recorder died are lost: a chunk is only readable whole.
//!
//! Reading is sequential (`mcap::MessageStream`): it does not need the summary section at the end
//! of the file, which a killed recorder never wrote.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::Path;
use std::sync::Arc;

use crate::cdr::{self, Recordable};
use crate::error::{DecodeError, ReadError};
use crate::schema::{self, StructLayout};
use crate::writer::{MESSAGE_ENCODING, META_PAYLOAD_VERSION, META_TYPE_NAME};

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
}

/// A message that was skipped, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    /// Its topic.
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
    /// Messages skipped (see [`Messages::skipped_count`]).
    pub skipped_count: u64,
    /// The first [`MAX_SKIP_DETAILS`] skipped messages.
    pub skipped: Vec<Skipped>,
    /// Where reading stopped early and why (a cut-off file), `None` for a complete file.
    pub damage: Option<String>,
}

/// Reads the recording at `path` whole (see the module documentation for what is refused and
/// what is skipped).
pub fn read_file(path: impl AsRef<Path>) -> Result<Recording, ReadError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    read_bytes(&bytes, &path.display().to_string())
}

/// Reads a recording held in `bytes`; `origin` names it in errors (a path, say).
pub fn read_bytes(bytes: &[u8], origin: &str) -> Result<Recording, ReadError> {
    let mut messages = Messages::new(bytes, origin)?;
    let mut out = Vec::new();
    for message in &mut messages {
        out.push(message?);
    }
    Ok(Recording {
        messages: out,
        skipped_count: messages.skipped_count,
        skipped: messages.skipped,
        damage: messages.damage,
    })
}

/// What a channel's metadata resolved to.
struct ChannelInfo {
    topic: Arc<str>,
    layout: &'static StructLayout,
}

/// The messages of a recording, one at a time, in file order: for a recording too large to
/// hold decoded in memory. Ends at the first error (`Some(Err)`, then `None`).
pub struct Messages<'a> {
    stream: mcap::MessageStream<'a>,
    channels: HashMap<u16, ChannelInfo>,
    skipped_count: u64,
    skipped: Vec<Skipped>,
    damage: Option<String>,
    done: bool,
}

impl std::fmt::Debug for Messages<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Messages")
            .field("skipped_count", &self.skipped_count)
            .field("damage", &self.damage)
            .finish_non_exhaustive()
    }
}

impl<'a> Messages<'a> {
    /// Starts reading the recording in `bytes`; `origin` names it in errors.
    pub fn new(bytes: &'a [u8], origin: &str) -> Result<Self, ReadError> {
        // The stream would only notice at its first record; a file that is not MCAP at all is an
        // error, not a damaged recording.
        if !bytes.starts_with(mcap::MAGIC) {
            return Err(ReadError::NotMcap {
                origin: origin.to_string(),
                source: mcap::McapError::BadMagic,
            });
        }
        let stream = mcap::MessageStream::new(bytes).map_err(|source| ReadError::NotMcap {
            origin: origin.to_string(),
            source,
        })?;
        Ok(Self {
            stream,
            channels: HashMap::new(),
            skipped_count: 0,
            skipped: Vec::new(),
            damage: None,
            done: false,
        })
    }

    /// Messages skipped so far.
    pub fn skipped_count(&self) -> u64 {
        self.skipped_count
    }

    /// The first [`MAX_SKIP_DETAILS`] messages skipped so far.
    pub fn skipped(&self) -> &[Skipped] {
        &self.skipped
    }

    /// Where reading stopped early and why, once it has.
    pub fn damage(&self) -> Option<&str> {
        self.damage.as_deref()
    }

    fn skip(&mut self, topic: &str, log_time_ns: u64, reason: SkipReason) {
        self.skipped_count += 1;
        if self.skipped.len() < MAX_SKIP_DETAILS {
            self.skipped.push(Skipped {
                topic: topic.to_string(),
                log_time_ns,
                reason,
            });
        }
    }
}

/// Checks a channel's metadata against this build's payloads.
fn check_channel(channel: &mcap::Channel<'_>) -> Result<ChannelInfo, ReadError> {
    let topic = channel.topic.clone();
    if channel.message_encoding != MESSAGE_ENCODING {
        return Err(ReadError::Encoding {
            topic,
            encoding: channel.message_encoding.clone(),
        });
    }
    let type_name = channel
        .metadata
        .get(META_TYPE_NAME)
        .cloned()
        .unwrap_or_default();
    let Some(layout) = schema::payload_by_type_name(&type_name) else {
        return Err(ReadError::UnknownType { topic, type_name });
    };
    let version = channel.metadata.get(META_PAYLOAD_VERSION);
    if version.and_then(|v| v.parse::<u16>().ok()) != Some(ipc_types::PAYLOAD_VERSION) {
        return Err(ReadError::VersionMismatch {
            topic,
            found: version.cloned().unwrap_or_else(|| "(none)".to_string()),
            expected: ipc_types::PAYLOAD_VERSION,
        });
    }
    Ok(ChannelInfo {
        topic: Arc::from(topic),
        layout,
    })
}

impl Iterator for Messages<'_> {
    type Item = Result<RecordedMessage, ReadError>;

    fn next(&mut self) -> Option<Self::Item> {
        while !self.done {
            let message = match self.stream.next() {
                None => {
                    self.done = true;
                    return None;
                }
                Some(Err(e)) => {
                    // Past the start magic, any error is damage: keep what was read.
                    self.damage = Some(e.to_string());
                    self.done = true;
                    return None;
                }
                Some(Ok(message)) => message,
            };
            let channel_id = message.channel.id;
            let info = match self.channels.entry(channel_id) {
                Entry::Occupied(entry) => entry.into_mut(),
                Entry::Vacant(entry) => match check_channel(&message.channel) {
                    Ok(info) => entry.insert(info),
                    Err(e) => {
                        self.done = true;
                        return Some(Err(e));
                    }
                },
            };
            let (topic, layout) = (Arc::clone(&info.topic), info.layout);
            let data = message.data;
            let expected = cdr::CDR_LE_HEADER.len() + layout.size;
            if data.len() != expected {
                let reason = SkipReason::WrongLength {
                    expected,
                    found: data.len(),
                };
                self.skip(&topic, message.log_time, reason);
                continue;
            }
            let Some(payload) = cdr::payload_of(&data) else {
                self.skip(&topic, message.log_time, SkipReason::NotCdr);
                continue;
            };
            // Every payload starts with its `version` (u16); a reader of a single message checks
            // it as the processes do.
            let version = payload.first_chunk::<2>().map(|v| u16::from_le_bytes(*v));
            if let Some(version) = version.filter(|v| *v != ipc_types::PAYLOAD_VERSION) {
                let reason = SkipReason::WrongVersion { found: version };
                self.skip(&topic, message.log_time, reason);
                continue;
            }
            return Some(Ok(RecordedMessage {
                topic,
                layout,
                log_time_ns: message.log_time,
                publish_time_ns: message.publish_time,
                sequence: message.sequence,
                payload: payload.to_vec(),
            }));
        }
        None
    }
}
