//! Reading a recording back: every message with its topic and times, its payload bytes checked
//! against this build's layouts.
//!
//! A channel recorded with another payload version or an unknown payload type stops the reading
//! with an error naming the topic: its bytes would be misread. Damage that only costs some
//! messages does not: a message of the wrong length (or without the CDR header, or with another
//! version in its `version` field, or of a channel never defined) is skipped and counted with the
//! reason; a damaged chunk (its CRC does not match, it does not decompress, it declares more than
//! [`crate::MAX_CHUNK_BYTES`]) is skipped whole and counted, and reading goes on with the next
//! one; a file that ends early (the recorder was killed before it finished the file) yields every
//! message of its complete chunks, then reports where reading stopped in [`Messages::damage`].
//! The messages of the chunk being written when the recorder died are lost: a chunk is only
//! readable whole.
//!
//! Reading is sequential: it does not need the summary section at the end of the file, which a
//! killed recorder never wrote (when it is there, its channel definitions stand in for those of a
//! damaged chunk). The file is taken apart by [`crate::scan`], which allocates nothing from a
//! length the file declares before checking it.

use std::borrow::Cow;
use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::Path;
use std::sync::Arc;

use mcap::read::ChannelAccumulator;
use mcap::records::{MessageHeader, Record, op};

use crate::cdr;
use crate::channel_check::{ChannelInfo, check_channel};
use crate::error::ReadError;
use crate::recorded::{
    DamagedChunk, MAX_SKIP_DETAILS, RecordedMessage, Recording, SkipReason, Skipped,
};
use crate::scan::{self, Framing, MAX_RECORDING_BYTES};

/// The bytes of the recording file at `path`: a regular file (never a FIFO, a device or a
/// directory, which are refused at once) of at most [`MAX_RECORDING_BYTES`].
pub fn read_file_bytes(path: impl AsRef<Path>) -> Result<Vec<u8>, ReadError> {
    Ok(rins_regular_file::read_bounded(
        path.as_ref(),
        MAX_RECORDING_BYTES,
    )?)
}

/// Reads the recording at `path` whole (see the module documentation for what is refused and
/// what is skipped, and [`read_file_bytes`] for what the path must be).
pub fn read_file(path: impl AsRef<Path>) -> Result<Recording, ReadError> {
    let path = path.as_ref();
    let bytes = read_file_bytes(path)?;
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
        damaged_chunk_count: messages.damaged_chunk_count,
        damaged_chunks: messages.damaged_chunks,
        damage: messages.damage,
    })
}

/// The messages of a recording, one at a time, in file order: for a recording too large to
/// hold decoded in memory. Ends at the first error (`Some(Err)`, then `None`).
pub struct Messages<'a> {
    bytes: &'a [u8],
    /// Where the next record outside a chunk starts.
    pos: usize,
    /// The chunk being read, if any.
    chunk: Option<ChunkCursor<'a>>,
    /// Schemas and channels as defined so far.
    defined: ChannelAccumulator<'static>,
    /// Channels checked against this build, by id.
    channels: HashMap<u16, ChannelInfo>,
    skipped_count: u64,
    skipped: Vec<Skipped>,
    damaged_chunk_count: u64,
    damaged_chunks: Vec<DamagedChunk>,
    damage: Option<String>,
    done: bool,
}

/// The records of one chunk, and how far they have been read.
struct ChunkCursor<'a> {
    records: Cow<'a, [u8]>,
    pos: usize,
    /// Where the chunk starts in the file.
    offset: usize,
}

/// What one record brought.
enum Outcome {
    /// Nothing to hand out (a schema, a channel, an index, a skipped message).
    Nothing,
    /// A message, or the error that ends the reading.
    Item(Result<RecordedMessage, ReadError>),
    /// The record is damaged; so is the chunk holding it.
    Damaged(String),
}

impl std::fmt::Debug for Messages<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Messages")
            .field("skipped_count", &self.skipped_count)
            .field("damaged_chunk_count", &self.damaged_chunk_count)
            .field("damage", &self.damage)
            .finish_non_exhaustive()
    }
}

impl<'a> Messages<'a> {
    /// Starts reading the recording in `bytes`; `origin` names it in errors.
    pub fn new(bytes: &'a [u8], origin: &str) -> Result<Self, ReadError> {
        // A file that is not MCAP at all is an error, not a damaged recording.
        if !bytes.starts_with(mcap::MAGIC) {
            return Err(ReadError::NotMcap {
                origin: origin.to_string(),
                source: mcap::McapError::BadMagic,
            });
        }
        let mut messages = Self {
            bytes,
            pos: mcap::MAGIC.len(),
            chunk: None,
            defined: ChannelAccumulator::default(),
            channels: HashMap::new(),
            skipped_count: 0,
            skipped: Vec::new(),
            damaged_chunk_count: 0,
            damaged_chunks: Vec::new(),
            damage: None,
            done: false,
        };
        messages.define_from_summary();
        Ok(messages)
    }

    /// Takes in the schemas and channels the summary section repeats, when the file has one: the
    /// writer defines a channel once, in the chunk of its first message, and when that chunk is
    /// damaged the messages of every later chunk would otherwise have no channel. A damaged
    /// summary only costs this help.
    fn define_from_summary(&mut self) {
        // The footer record (opcode, length 20, summary start, summary offset start, CRC), then
        // the closing magic.
        const FOOTER_RECORD: usize = 1 + 8 + 20;
        let bytes = self.bytes;
        let Some(footer_at) = bytes.len().checked_sub(mcap::MAGIC.len() + FOOTER_RECORD) else {
            return;
        };
        if !bytes.ends_with(mcap::MAGIC) {
            return;
        }
        let Framing::Record { opcode, body } = scan::frame(bytes, footer_at) else {
            return;
        };
        let Some(start) = bytes[body.clone()].first_chunk::<8>() else {
            return;
        };
        let start = u64::from_le_bytes(*start);
        // Zero: no summary; otherwise it lies between the data section and the footer.
        let Ok(mut pos) = usize::try_from(start) else {
            return;
        };
        if opcode != op::FOOTER || body.len() != 20 || pos == 0 || pos >= footer_at {
            return;
        }
        let summary = &bytes[..footer_at];
        while let Framing::Record { opcode, body } = scan::frame(summary, pos) {
            pos = body.end;
            if matches!(opcode, op::SCHEMA | op::CHANNEL) {
                // Definitions only: nothing to hand out, and a damaged one is no loss.
                let _ = self.record(opcode, &summary[body]);
            }
        }
    }

    /// Messages skipped so far.
    pub fn skipped_count(&self) -> u64 {
        self.skipped_count
    }

    /// The first [`MAX_SKIP_DETAILS`] messages skipped so far.
    pub fn skipped(&self) -> &[Skipped] {
        &self.skipped
    }

    /// Chunks skipped so far as damaged: a CRC that does not match, data that does not
    /// decompress, a declared size beyond [`crate::MAX_CHUNK_BYTES`], a record that overruns the
    /// chunk or the file. Their messages are lost (and not counted in [`Self::skipped_count`]: a
    /// damaged chunk does not say how many it held).
    pub fn damaged_chunk_count(&self) -> u64 {
        self.damaged_chunk_count
    }

    /// The first [`MAX_SKIP_DETAILS`] chunks skipped so far as damaged.
    pub fn damaged_chunks(&self) -> &[DamagedChunk] {
        &self.damaged_chunks
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

    fn damaged(&mut self, offset: usize, reason: String) {
        self.damaged_chunk_count += 1;
        if self.damaged_chunks.len() < MAX_SKIP_DETAILS {
            self.damaged_chunks.push(DamagedChunk {
                offset: offset as u64,
                reason,
            });
        }
    }

    /// Takes in one record (of a chunk, or outside any).
    fn record(&mut self, opcode: u8, body: &[u8]) -> Outcome {
        if !scan::lengths_fit(opcode, body) {
            return Outcome::Damaged(format!("a record (opcode {opcode:#04x}) overruns itself"));
        }
        let parsed = match opcode {
            op::SCHEMA | op::CHANNEL | op::MESSAGE => mcap::parse_record(opcode, body),
            // Indexes, attachments, metadata, statistics: nothing a reader of payloads needs.
            _ => return Outcome::Nothing,
        };
        let defined = match parsed {
            Ok(Record::Schema { header, data }) => {
                self.defined.add_schema_from_slice(header, &data)
            }
            Ok(Record::Channel(channel)) => self.defined.add_channel(channel),
            Ok(Record::Message { header, data }) => return self.message(header, &data),
            Ok(_) => Ok(()),
            Err(e) => Err(e),
        };
        match defined {
            Ok(()) => Outcome::Nothing,
            Err(e) => Outcome::Damaged(e.to_string()),
        }
    }

    /// Checks one message.
    fn message(&mut self, header: MessageHeader, data: &[u8]) -> Outcome {
        let channel_id = header.channel_id;
        let info = match self.channels.entry(channel_id) {
            Entry::Occupied(entry) => entry.into_mut(),
            Entry::Vacant(entry) => {
                let Some(channel) = self.defined.get(channel_id) else {
                    let topic = format!("channel {channel_id}");
                    let reason = SkipReason::UnknownChannel {
                        channel: channel_id,
                    };
                    self.skip(&topic, header.log_time, reason);
                    return Outcome::Nothing;
                };
                match check_channel(&channel) {
                    Ok(info) => entry.insert(info),
                    Err(e) => return Outcome::Item(Err(e)),
                }
            }
        };
        let (topic, layout) = (Arc::clone(&info.topic), info.layout);
        let expected = cdr::CDR_LE_HEADER.len() + layout.size;
        if data.len() != expected {
            let reason = SkipReason::WrongLength {
                expected,
                found: data.len(),
            };
            self.skip(&topic, header.log_time, reason);
            return Outcome::Nothing;
        }
        let Some(payload) = cdr::payload_of(data) else {
            self.skip(&topic, header.log_time, SkipReason::NotCdr);
            return Outcome::Nothing;
        };
        // Every payload starts with its `version` (u16); a reader of a single message checks
        // it as the processes do.
        let version = payload.first_chunk::<2>().map(|v| u16::from_le_bytes(*v));
        if let Some(version) = version.filter(|v| *v != ipc_types::PAYLOAD_VERSION) {
            let reason = SkipReason::WrongVersion { found: version };
            self.skip(&topic, header.log_time, reason);
            return Outcome::Nothing;
        }
        Outcome::Item(Ok(RecordedMessage {
            topic,
            layout,
            log_time_ns: header.log_time,
            publish_time_ns: header.publish_time,
            sequence: header.sequence,
            payload: payload.to_vec(),
        }))
    }

    /// The next record of the chunk being read, taken in; `None` when no chunk is being read.
    fn next_in_chunk(&mut self) -> Option<Outcome> {
        let mut chunk = self.chunk.take()?;
        match scan::frame(&chunk.records, chunk.pos) {
            Framing::End => Some(Outcome::Nothing),
            Framing::Overrun(why) => {
                self.damaged(chunk.offset, why);
                Some(Outcome::Nothing)
            }
            Framing::Record { opcode, body } => {
                chunk.pos = body.end;
                let outcome = self.record(opcode, &chunk.records[body]);
                match &outcome {
                    Outcome::Damaged(why) => self.damaged(chunk.offset, why.clone()),
                    Outcome::Item(Err(_)) => {}
                    Outcome::Nothing | Outcome::Item(Ok(_)) => self.chunk = Some(chunk),
                }
                Some(outcome)
            }
        }
    }

    /// The next record outside any chunk, taken in (a chunk's records are then read from
    /// [`Self::chunk`]).
    fn next_in_file(&mut self) -> Outcome {
        let bytes = self.bytes;
        let at = self.pos;
        match scan::frame(bytes, at) {
            Framing::End => {
                self.damage = Some(format!(
                    "the file ends at byte {at} without its data end record: the recording was \
                     not finished"
                ));
                self.done = true;
                Outcome::Nothing
            }
            Framing::Overrun(why) => {
                // Either the last record is cut off, or a damaged length lost the framing: then
                // reading resumes at the next chunk.
                match scan::find_chunk(bytes, at + 1) {
                    Some(next) => {
                        self.damaged(at, why);
                        self.pos = next;
                    }
                    None => {
                        self.damage = Some(format!("the file is cut off at byte {at}: {why}"));
                        self.done = true;
                    }
                }
                Outcome::Nothing
            }
            Framing::Record { opcode, body } => {
                self.pos = body.end;
                match opcode {
                    op::CHUNK => match scan::chunk_records(&bytes[body]) {
                        Ok(records) => {
                            self.chunk = Some(ChunkCursor {
                                records,
                                pos: 0,
                                offset: at,
                            });
                        }
                        Err(why) => self.damaged(at, why),
                    },
                    // The data section ends here (a data end record has a 4-byte CRC): the
                    // summary after it repeats what was read.
                    op::DATA_END if body.len() == 4 => self.done = true,
                    _ => {
                        let outcome = self.record(opcode, &bytes[body]);
                        if let Outcome::Damaged(why) = outcome {
                            self.damaged(at, why);
                            return Outcome::Nothing;
                        }
                        return outcome;
                    }
                }
                Outcome::Nothing
            }
        }
    }
}

impl Iterator for Messages<'_> {
    type Item = Result<RecordedMessage, ReadError>;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            let outcome = match self.next_in_chunk() {
                Some(outcome) => outcome,
                None if self.done => return None,
                None => self.next_in_file(),
            };
            match outcome {
                Outcome::Item(Ok(message)) => return Some(Ok(message)),
                Outcome::Item(Err(e)) => {
                    self.done = true;
                    self.chunk = None;
                    return Some(Err(e));
                }
                Outcome::Nothing | Outcome::Damaged(_) => {}
            }
        }
    }
}
