//! What can go wrong while recording or reading a recording; every error names the file or the
//! topic it is about, so that a message on its own tells what to look at.

use std::path::PathBuf;

/// An error while writing a recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The file exists and overwriting was not asked for.
    #[error("{path} exists; refusing to overwrite it")]
    Exists {
        /// The recording's path.
        path: PathBuf,
    },
    /// The path names a directory (or another non-file), which overwriting must not remove.
    #[error("{path} is not a regular file; refusing to replace it")]
    NotAFile {
        /// The recording's path.
        path: PathBuf,
    },
    /// Creating, writing or closing the file failed.
    #[error("{path}: {source}")]
    Io {
        /// The recording's path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The MCAP writer failed (usually an I/O error underneath).
    #[error("{path}: writing MCAP: {source}")]
    Mcap {
        /// The recording's path.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: mcap::McapError,
    },
    /// A topic was registered twice with different payload types.
    #[error("{path}: topic {topic} is already recorded as {existing}, not {requested}")]
    TopicConflict {
        /// The recording's path.
        path: PathBuf,
        /// The topic.
        topic: String,
        /// The type it was registered with first.
        existing: &'static str,
        /// The type asked for now.
        requested: &'static str,
    },
    /// A channel id that this recorder did not hand out.
    #[error("{path}: no channel {channel}")]
    UnknownChannel {
        /// The recording's path.
        path: PathBuf,
        /// The channel id given.
        channel: u16,
    },
    /// A payload whose length is not its channel's payload size.
    #[error("{path}: topic {topic} carries {expected}-byte payloads, got {found} bytes")]
    WrongLength {
        /// The recording's path.
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// The channel's payload size.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// A payload of another type than the channel's.
    #[error("{path}: topic {topic} carries {expected}, got {found}")]
    WrongType {
        /// The recording's path.
        path: PathBuf,
        /// The channel's topic.
        topic: String,
        /// The channel's payload type.
        expected: &'static str,
        /// The type given.
        found: &'static str,
    },
    /// The writer thread ended without a summary (it panicked).
    #[error("the recording's writer thread panicked")]
    WriterPanicked,
}

/// An error that stops reading a recording. Damage that only costs some messages (a wrong length,
/// a damaged chunk, a cut-off end) is reported in the [`crate::Recording`] instead.
#[derive(Debug, thiserror::Error)]
pub enum ReadError {
    /// The file could not be opened or read, or is no regular file, or is too large; the error
    /// names the path.
    #[error(transparent)]
    File(#[from] rins_regular_file::FileError),
    /// The bytes are not an MCAP file (no magic at the start).
    #[error("{origin}: not an MCAP recording")]
    NotMcap {
        /// The recording's path, or what the bytes are.
        origin: String,
        /// The underlying error.
        #[source]
        source: mcap::McapError,
    },
    /// A channel records payloads of another layout version than this build's.
    #[error(
        "topic {topic}: recorded with payload version {found}, this build reads version {expected}"
    )]
    VersionMismatch {
        /// The channel's topic.
        topic: String,
        /// The version the channel's metadata states (as written, possibly not a number).
        found: String,
        /// [`ipc_types::PAYLOAD_VERSION`].
        expected: u16,
    },
    /// A channel whose payload type this build does not know (or that states none).
    #[error("topic {topic}: unknown payload type {type_name:?}")]
    UnknownType {
        /// The channel's topic.
        topic: String,
        /// The type name the channel's metadata states (empty when absent).
        type_name: String,
    },
    /// A channel whose messages are not CDR.
    #[error("topic {topic}: message encoding {encoding:?}, expected \"cdr\"")]
    Encoding {
        /// The channel's topic.
        topic: String,
        /// The encoding the channel states.
        encoding: String,
    },
}

/// Why a recorded message could not be decoded as the payload asked for.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DecodeError {
    /// The message is of another payload type.
    #[error("topic {topic}: the message is a {found}, not a {expected}")]
    WrongType {
        /// The message's topic.
        topic: String,
        /// The type asked for.
        expected: &'static str,
        /// The message's type.
        found: &'static str,
    },
    /// The message's length is not the payload's size.
    #[error("topic {topic}: {found} bytes, a {expected_type} has {expected}")]
    WrongLength {
        /// The message's topic.
        topic: String,
        /// The type asked for.
        expected_type: &'static str,
        /// The payload's size.
        expected: usize,
        /// The message's length.
        found: usize,
    },
}
