//! Writing payloads into an MCAP file: one schema (ROS 2 `.msg` text) per payload type, one
//! channel per topic, one CDR message per sample, zstd-compressed chunks.

use std::collections::BTreeMap;
use std::fs::{File, OpenOptions};
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;

use crate::cdr::{self, Recordable};
use crate::error::RecordError;
use crate::schema::{self, StructLayout};

/// MCAP schema encoding of the schemas: ROS 2 message definitions.
pub const SCHEMA_ENCODING: &str = "ros2msg";
/// MCAP message encoding of the messages: CDR.
pub const MESSAGE_ENCODING: &str = "cdr";
/// Channel metadata key naming the payload's iceoryx2 type, e.g. `rins::NavState`.
pub const META_TYPE_NAME: &str = "type_name";
/// Channel metadata key giving the payload layout version ([`ipc_types::PAYLOAD_VERSION`]).
pub const META_PAYLOAD_VERSION: &str = "payload_version";
/// Channel metadata key giving the payload size in bytes.
pub const META_SIZE: &str = "size";

/// How to create a recording.
#[derive(Debug, Clone)]
pub struct RecordOptions {
    /// Replace an existing file at the path (a symbolic link there is replaced, never followed).
    /// Off by default: a recording is not overwritten by accident.
    pub overwrite: bool,
    /// The MCAP profile; `ros2`, the profile of ROS 2 message schemas with CDR messages.
    pub profile: String,
    /// Target uncompressed size of a chunk, bytes. A writer killed mid-chunk loses that chunk, so
    /// smaller chunks lose less at some cost in compression. At most half of
    /// [`crate::MAX_CHUNK_BYTES`] is used, so that every chunk written can be read back.
    pub chunk_size: u64,
}

impl Default for RecordOptions {
    fn default() -> Self {
        Self {
            overwrite: false,
            profile: "ros2".to_string(),
            chunk_size: 1024 * 1024,
        }
    }
}

/// A channel of a [`Recorder`], as [`Recorder::channel`] returned it: the index of the topic in
/// the order the topics were registered.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ChannelId(pub u16);

/// One topic of a finished recording.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicSummary {
    /// The topic.
    pub topic: String,
    /// The payload's type name, e.g. `rins::NavState`.
    pub type_name: &'static str,
    /// Samples written.
    pub written: u64,
    /// Samples dropped before they reached the file (the writer thread's queue was full).
    pub dropped: u64,
}

/// What a finished recording holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordSummary {
    /// The file.
    pub path: PathBuf,
    /// Samples written, all topics.
    pub samples_written: u64,
    /// Samples dropped, all topics.
    pub samples_dropped: u64,
    /// Per topic, in registration order.
    pub topics: Vec<TopicSummary>,
    /// Payload bytes written (without the CDR headers).
    pub payload_bytes: u64,
    /// Size of the finished file, bytes.
    pub file_bytes: u64,
}

struct Channel {
    topic: String,
    layout: &'static StructLayout,
    mcap_id: u16,
    sequence: u32,
    written: u64,
}

/// An MCAP recording being written. Not thread-safe by design: one thread owns it (see
/// [`crate::spawn_writer`] to feed it from others).
///
/// Dropping it without [`Recorder::finish`] still completes the file (the MCAP writer finishes
/// on drop), but errors then go unreported.
pub struct Recorder {
    path: PathBuf,
    writer: mcap::Writer<BufWriter<File>>,
    channels: Vec<Channel>,
    /// One message's encoding, reused: no allocation per message once it has grown.
    buf: Vec<u8>,
    samples_written: u64,
    payload_bytes: u64,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("path", &self.path)
            .field("samples_written", &self.samples_written)
            .finish_non_exhaustive()
    }
}

impl Recorder {
    /// Creates the recording at `path`. Refuses an existing file unless `options.overwrite`; never
    /// writes through a symbolic link someone left at the path.
    pub fn create(path: impl AsRef<Path>, options: &RecordOptions) -> Result<Self, RecordError> {
        let path = path.as_ref().to_path_buf();
        let file = create_file(&path, options.overwrite)?;
        Self::on_file(file, path, options)
    }

    /// A recording written into `file`, already open for writing, and named `path` in errors and
    /// the summary (`options.overwrite` does not apply: the file is whatever was opened).
    pub fn on_file(
        file: File,
        path: impl Into<PathBuf>,
        options: &RecordOptions,
    ) -> Result<Self, RecordError> {
        let path = path.into();
        let writer = mcap::WriteOptions::new()
            .compression(Some(mcap::Compression::Zstd))
            // Compress in the writing thread: the pipeline's processes need the other cores.
            .compression_threads(0)
            // A chunk ends once it holds the target size, so it can exceed it by one message and
            // the definitions written with it: half the reader's ceiling leaves ample room.
            .chunk_size(Some(options.chunk_size.min(crate::MAX_CHUNK_BYTES / 2)))
            .profile(options.profile.clone())
            .library(concat!("rins-recording ", env!("CARGO_PKG_VERSION")))
            .create(BufWriter::new(file))
            .map_err(|source| RecordError::Mcap {
                path: path.clone(),
                source,
            })?;
        Ok(Self {
            path,
            writer,
            channels: Vec::new(),
            buf: Vec::new(),
            samples_written: 0,
            payload_bytes: 0,
        })
    }

    /// The recording's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Registers `topic` carrying payloads of `layout` (its schema, once per type, and its
    /// channel, with the payload's type name, layout version and size as metadata). Registering a
    /// topic again with the same layout returns the same channel.
    pub fn channel(
        &mut self,
        topic: &str,
        layout: &'static StructLayout,
    ) -> Result<ChannelId, RecordError> {
        if let Some(index) = self.channels.iter().position(|c| c.topic == topic) {
            let existing = self.channels[index].layout;
            if !core::ptr::eq(existing, layout) {
                return Err(RecordError::TopicConflict {
                    path: self.path.clone(),
                    topic: topic.to_string(),
                    existing: existing.type_name,
                    requested: layout.type_name,
                });
            }
            return Ok(channel_id(index));
        }
        let text = schema::ros2msg(layout);
        let schema_id = self
            .writer
            .add_schema(&layout.schema_name(), SCHEMA_ENCODING, text.as_bytes())
            .map_err(|source| self.mcap_error(source))?;
        let metadata = BTreeMap::from([
            (META_TYPE_NAME.to_string(), layout.type_name.to_string()),
            (
                META_PAYLOAD_VERSION.to_string(),
                ipc_types::PAYLOAD_VERSION.to_string(),
            ),
            (META_SIZE.to_string(), layout.size.to_string()),
        ]);
        let mcap_id = self
            .writer
            .add_channel(schema_id, topic, MESSAGE_ENCODING, &metadata)
            .map_err(|source| self.mcap_error(source))?;
        self.channels.push(Channel {
            topic: topic.to_string(),
            layout,
            mcap_id,
            sequence: 0,
            written: 0,
        });
        Ok(channel_id(self.channels.len() - 1))
    }

    /// [`Recorder::channel`] for the payload type `T`.
    pub fn channel_for<T: Recordable>(&mut self, topic: &str) -> Result<ChannelId, RecordError> {
        self.channel(topic, T::layout())
    }

    /// The topic and layout of a registered channel.
    pub fn channel_info(&self, channel: ChannelId) -> Option<(&str, &'static StructLayout)> {
        self.channels
            .get(usize::from(channel.0))
            .map(|c| (c.topic.as_str(), c.layout))
    }

    /// Writes one sample: `payload` must be the bytes of one payload of the channel's type.
    /// `log_time_ns` is when the recorder received it, `publish_time_ns` when it was published
    /// (both as the caller's clock has them; rins uses CLOCK_MONOTONIC).
    pub fn write(
        &mut self,
        channel: ChannelId,
        log_time_ns: u64,
        publish_time_ns: u64,
        payload: &[u8],
    ) -> Result<(), RecordError> {
        let Some(entry) = self.channels.get_mut(usize::from(channel.0)) else {
            return Err(RecordError::UnknownChannel {
                path: self.path.clone(),
                channel: channel.0,
            });
        };
        if payload.len() != entry.layout.size {
            return Err(RecordError::WrongLength {
                path: self.path.clone(),
                topic: entry.topic.clone(),
                expected: entry.layout.size,
                found: payload.len(),
            });
        }
        let header = MessageHeader {
            channel_id: entry.mcap_id,
            sequence: entry.sequence,
            log_time: log_time_ns,
            publish_time: publish_time_ns,
        };
        self.buf.clear();
        cdr::encode_into(payload, &mut self.buf);
        if let Err(source) = self.writer.write_to_known_channel(&header, &self.buf) {
            return Err(RecordError::Mcap {
                path: self.path.clone(),
                source,
            });
        }
        entry.sequence = entry.sequence.wrapping_add(1);
        entry.written += 1;
        self.samples_written += 1;
        self.payload_bytes += payload.len() as u64;
        Ok(())
    }

    /// [`Recorder::write`] of a typed payload; refuses a payload of another type than the
    /// channel's.
    pub fn write_payload<T: Recordable>(
        &mut self,
        channel: ChannelId,
        log_time_ns: u64,
        publish_time_ns: u64,
        payload: &T,
    ) -> Result<(), RecordError> {
        if let Some((topic, layout)) = self.channel_info(channel)
            && !core::ptr::eq(layout, T::layout())
        {
            return Err(RecordError::WrongType {
                path: self.path.clone(),
                topic: topic.to_string(),
                expected: layout.type_name,
                found: T::layout().type_name,
            });
        }
        self.write(channel, log_time_ns, publish_time_ns, payload.as_bytes())
    }

    /// Samples written so far.
    pub fn samples_written(&self) -> u64 {
        self.samples_written
    }

    /// Writes the last chunk, the summary and the footer, and flushes the file to disk.
    pub fn finish(mut self) -> Result<RecordSummary, RecordError> {
        self.writer.finish().map_err(|source| RecordError::Mcap {
            path: self.path.clone(),
            source,
        })?;
        let path = self.path;
        let io = |source: std::io::Error| RecordError::Io {
            path: path.clone(),
            source,
        };
        let mut buffered = self.writer.into_inner();
        buffered.flush().map_err(io)?;
        let file = buffered.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        let file_bytes = file.metadata().map_err(io)?.len();
        let topics = self
            .channels
            .iter()
            .map(|c| TopicSummary {
                topic: c.topic.clone(),
                type_name: c.layout.type_name,
                written: c.written,
                dropped: 0,
            })
            .collect();
        Ok(RecordSummary {
            path,
            samples_written: self.samples_written,
            samples_dropped: 0,
            topics,
            payload_bytes: self.payload_bytes,
            file_bytes,
        })
    }

    fn mcap_error(&self, source: mcap::McapError) -> RecordError {
        RecordError::Mcap {
            path: self.path.clone(),
            source,
        }
    }
}

fn channel_id(index: usize) -> ChannelId {
    // MCAP channel ids are u16, so the writer refuses a 65 537th channel before this could wrap.
    ChannelId(u16::try_from(index).unwrap_or(u16::MAX))
}

/// Creates a new file at `path` without following a symbolic link: `create_new` (`O_EXCL`) fails
/// on anything already there, links included. With `overwrite`, a file or link already there is
/// removed first (the link itself, not its target); should someone plant another in between,
/// `create_new` fails rather than follow it.
pub fn create_file(path: &Path, overwrite: bool) -> Result<File, RecordError> {
    let io = |source: std::io::Error| RecordError::Io {
        path: path.to_path_buf(),
        source,
    };
    if overwrite {
        match std::fs::symlink_metadata(path) {
            Ok(meta) if meta.is_file() || meta.file_type().is_symlink() => {
                std::fs::remove_file(path).map_err(io)?;
            }
            Ok(_) => {
                return Err(RecordError::NotAFile {
                    path: path.to_path_buf(),
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(io(e)),
        }
    }
    OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(path)
        .map_err(|source| {
            if source.kind() == std::io::ErrorKind::AlreadyExists {
                RecordError::Exists {
                    path: path.to_path_buf(),
                }
            } else {
                io(source)
            }
        })
}
