//! Recording rins payloads to MCAP files, and reading them back.
//!
//! A recording keeps the samples the processes exchange exactly as they travel: each payload's
//! bytes, stamped with the time the recorder received it, one MCAP channel per topic. The files
//! open in Foxglove and any MCAP tool as ROS 2 data: every payload type has a ROS 2 message
//! definition (schema encoding `ros2msg`) written from its Rust layout, and a payload's bytes
//! behind a 4-byte CDR header are its CDR encoding, because the payloads are `#[repr(C)]` with
//! every field naturally aligned and no hidden padding.
//!
//! - [`schema`]: each payload's layout from `offset_of!`, and its `.msg` text;
//! - [`cdr`]: payloads to CDR messages and back ([`Recordable`]);
//! - [`Recorder`]: the MCAP writer; [`spawn_writer`] puts it behind a queue that never blocks the
//!   threads taking samples in, and counts what it drops;
//! - [`read_file`] / [`Messages`]: reading back, refusing channels of another payload version,
//!   skipping (and counting) damaged messages and chunks, and keeping what a cut-off file still
//!   holds; a recording path must be a regular file of at most [`MAX_RECORDING_BYTES`], and no
//!   length the file declares is allocated before it is checked.
//!
//! Each channel's metadata names the payload type (`type_name`, e.g. `rins::NavState`), its
//! layout version (`payload_version`, [`ipc_types::PAYLOAD_VERSION`]) and size, so that a reader
//! never misreads a recording made by another build.

pub mod cdr;
mod channel_check;
mod error;
mod reader;
mod recorded;
mod scan;
pub mod schema;
mod threaded;
mod topics;
mod writer;

pub use cdr::Recordable;
pub use error::{DecodeError, ReadError, RecordError};
pub use reader::{Messages, read_bytes, read_file, read_file_bytes};
pub use recorded::{
    DamagedChunk, MAX_SKIP_DETAILS, RecordedMessage, Recording, SkipReason, Skipped, decode,
};
pub use scan::{MAX_CHUNK_BYTES, MAX_RECORDING_BYTES};
pub use schema::{MAX_PAYLOAD, StructLayout};
pub use threaded::{
    Dropped, RecordReceiver, RecordSender, join_writer, record_channel, spawn_writer,
};
pub use topics::{TOPICS, layout_of_topic};
pub use writer::{
    ChannelId, MESSAGE_ENCODING, META_PAYLOAD_VERSION, META_SIZE, META_TYPE_NAME, RecordOptions,
    RecordSummary, Recorder, SCHEMA_ENCODING, TopicSummary, create_file,
};
