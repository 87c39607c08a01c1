//! Errors of the frame codec. Each names the offending field and value.

use core::fmt;

use super::frame::FrameType;

/// Why a frame could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EncodeError {
    /// The output buffer is shorter than the encoded frame.
    BufferTooSmall { needed: usize, available: usize },
    /// A channel count exceeds what the payload can carry.
    TooManyChannels {
        field: &'static str,
        value: u8,
        max: usize,
    },
    /// A gyro or accelerometer count lies outside the 12-bit range -2048..=2047.
    CountOutOfRange {
        field: &'static str,
        index: usize,
        value: i16,
    },
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EncodeError::BufferTooSmall { needed, available } => write!(
                f,
                "output buffer too small: frame needs {needed} bytes, buffer has {available}"
            ),
            EncodeError::TooManyChannels { field, value, max } => {
                write!(f, "{field} = {value} exceeds the maximum of {max}")
            }
            EncodeError::CountOutOfRange {
                field,
                index,
                value,
            } => write!(
                f,
                "{field}[{index}] = {value} is outside the 12-bit range -2048..=2047"
            ),
        }
    }
}

impl std::error::Error for EncodeError {}

/// Why bytes could not be decoded as one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecodeError {
    /// The bytes do not start with the sync word.
    NoSync,
    /// The bytes so far are a valid beginning; the whole frame needs `needed` bytes.
    Incomplete { needed: usize },
    /// The type byte names no known frame type.
    UnknownFrameType { value: u8 },
    /// The length byte (or the payload's own channel counts) disagree with the frame type.
    BadPayloadLength { frame_type: FrameType, len: usize },
    /// The CRC-32C trailer does not match the frame.
    CrcMismatch { received: u32, computed: u32 },
    /// An IMU channel count exceeds what the payload can carry.
    TooManyChannels {
        field: &'static str,
        value: u8,
        max: usize,
    },
    /// A gyro or accelerometer count lies outside the 12-bit range -2048..=2047.
    CountOutOfRange {
        field: &'static str,
        index: usize,
        value: i16,
    },
}

impl DecodeError {
    /// Whether the error is a CRC mismatch (as opposed to a frame that is malformed in itself).
    pub fn is_crc(&self) -> bool {
        matches!(self, DecodeError::CrcMismatch { .. })
    }
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::NoSync => write!(f, "bytes do not start with the sync word A5 5A"),
            DecodeError::Incomplete { needed } => {
                write!(f, "incomplete frame: {needed} bytes needed")
            }
            DecodeError::UnknownFrameType { value } => {
                write!(f, "frame type = {value:#04x} is not a known frame type")
            }
            DecodeError::BadPayloadLength { frame_type, len } => {
                write!(
                    f,
                    "payload length = {len} is invalid for a {frame_type:?} frame"
                )
            }
            DecodeError::CrcMismatch { received, computed } => write!(
                f,
                "crc = {received:#010x} does not match the computed {computed:#010x}"
            ),
            DecodeError::TooManyChannels { field, value, max } => {
                write!(f, "{field} = {value} exceeds the maximum of {max}")
            }
            DecodeError::CountOutOfRange {
                field,
                index,
                value,
            } => write!(
                f,
                "{field}[{index}] = {value} is outside the 12-bit range -2048..=2047"
            ),
        }
    }
}

impl std::error::Error for DecodeError {}
