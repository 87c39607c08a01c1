//! Errors of the frame codec. Each names the offending field and value.

use core::fmt;

use crate::frame_type::FrameType;

/// An IMU frame whose content breaks the format's limits: the same limits bind what is encoded
/// and what is decoded, so both errors carry this one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImuContentError {
    /// A channel count exceeds what the payload can carry.
    TooManyChannels {
        /// The count's field name (`n_gyro`, `n_accel`, `n_temperature`).
        field: &'static str,
        /// The count given or received.
        value: u8,
        /// The largest count the payload carries.
        max: usize,
    },
    /// A gyro or accelerometer count lies outside the 12-bit range -2048..=2047.
    CountOutOfRange {
        /// The sample array's field name (`gyro_counts` or `accel_counts`).
        field: &'static str,
        /// The channel index within that array.
        index: usize,
        /// The out-of-range count.
        value: i16,
    },
}

impl fmt::Display for ImuContentError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ImuContentError::TooManyChannels { field, value, max } => {
                write!(f, "{field} = {value} exceeds the maximum of {max}")
            }
            ImuContentError::CountOutOfRange {
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

impl std::error::Error for ImuContentError {}

/// A field of a fixed-size frame (not the IMU's, see [`ImuContentError`]) whose value no working
/// sensor of its kind can produce: a valid CRC does not make a value sane. The same limits bind
/// what is encoded and what is decoded.
#[derive(Debug, Clone, Copy)]
pub struct ValueOutOfRange {
    /// The frame type that carried the value.
    pub frame_type: FrameType,
    /// The field's name (e.g. `diff_pressure_pa`).
    pub field: &'static str,
    /// The value given or received (NaN and infinities included).
    pub value: f64,
    /// Lowest sane value.
    pub min: f64,
    /// Highest sane value.
    pub max: f64,
}

impl ValueOutOfRange {
    /// `Ok` when `value` is finite and within `min..=max`, else the error naming `field`.
    pub fn check(
        frame_type: FrameType,
        field: &'static str,
        value: f64,
        min: f64,
        max: f64,
    ) -> Result<(), Self> {
        if value.is_finite() && (min..=max).contains(&value) {
            Ok(())
        } else {
            Err(Self {
                frame_type,
                field,
                value,
                min,
                max,
            })
        }
    }
}

// Compared bit for bit so that a NaN value equals itself: the error is a record of what arrived.
impl PartialEq for ValueOutOfRange {
    fn eq(&self, other: &Self) -> bool {
        self.frame_type == other.frame_type
            && self.field == other.field
            && self.value.to_bits() == other.value.to_bits()
            && self.min.to_bits() == other.min.to_bits()
            && self.max.to_bits() == other.max.to_bits()
    }
}

impl Eq for ValueOutOfRange {}

impl fmt::Display for ValueOutOfRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} frame: {} = {} is outside {}..={}",
            self.frame_type.name(),
            self.field,
            self.value,
            self.min,
            self.max
        )
    }
}

impl std::error::Error for ValueOutOfRange {}

/// Contents a frame may not carry, whichever way it travels: what a frame type's sanity check
/// ([`crate::SensorFrame::check_sane`]) refuses. Encoding and decoding report it as their own
/// `Content` or `OutOfRange` error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContentError {
    /// The IMU frame's content breaks the format's limits.
    Imu(ImuContentError),
    /// A fixed-size frame carries a value no working sensor produces.
    OutOfRange(ValueOutOfRange),
}

impl fmt::Display for ContentError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ContentError::Imu(e) => e.fmt(f),
            ContentError::OutOfRange(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for ContentError {}

impl From<ImuContentError> for ContentError {
    fn from(e: ImuContentError) -> Self {
        ContentError::Imu(e)
    }
}

impl From<ValueOutOfRange> for ContentError {
    fn from(e: ValueOutOfRange) -> Self {
        ContentError::OutOfRange(e)
    }
}

impl From<ContentError> for EncodeError {
    fn from(e: ContentError) -> Self {
        match e {
            ContentError::Imu(e) => EncodeError::Content(e),
            ContentError::OutOfRange(e) => EncodeError::OutOfRange(e),
        }
    }
}

impl From<ContentError> for DecodeError {
    fn from(e: ContentError) -> Self {
        match e {
            ContentError::Imu(e) => DecodeError::Content(e),
            ContentError::OutOfRange(e) => DecodeError::OutOfRange(e),
        }
    }
}

impl From<ValueOutOfRange> for EncodeError {
    fn from(e: ValueOutOfRange) -> Self {
        EncodeError::OutOfRange(e)
    }
}

impl From<ValueOutOfRange> for DecodeError {
    fn from(e: ValueOutOfRange) -> Self {
        DecodeError::OutOfRange(e)
    }
}

impl From<ImuContentError> for EncodeError {
    fn from(e: ImuContentError) -> Self {
        EncodeError::Content(e)
    }
}

impl From<ImuContentError> for DecodeError {
    fn from(e: ImuContentError) -> Self {
        DecodeError::Content(e)
    }
}

/// Why a frame could not be encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EncodeError {
    /// The output buffer is shorter than the encoded frame.
    BufferTooSmall {
        /// Bytes the encoded frame takes.
        needed: usize,
        /// Bytes the caller's buffer has.
        available: usize,
    },
    /// The IMU frame's content breaks the format's limits.
    Content(ImuContentError),
    /// A fixed-size frame carries a value no working sensor produces.
    OutOfRange(ValueOutOfRange),
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EncodeError::BufferTooSmall { needed, available } => write!(
                f,
                "output buffer too small: frame needs {needed} bytes, buffer has {available}"
            ),
            EncodeError::Content(e) => e.fmt(f),
            EncodeError::OutOfRange(e) => e.fmt(f),
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
    Incomplete {
        /// Bytes needed in all: the header's length until the header is complete, then the whole
        /// frame's.
        needed: usize,
    },
    /// The type byte names no known frame type.
    UnknownFrameType {
        /// The type byte received.
        value: u8,
    },
    /// The length byte (or the payload's own channel counts) disagree with the frame type.
    BadPayloadLength {
        /// The frame type the type byte named.
        frame_type: FrameType,
        /// The payload length received, bytes.
        len: usize,
    },
    /// The CRC-32C trailer does not match the frame.
    CrcMismatch {
        /// The CRC-32C in the frame's trailer.
        received: u32,
        /// The CRC-32C computed over the frame's bytes.
        computed: u32,
    },
    /// The IMU frame's content breaks the format's limits (valid CRC, insane values).
    Content(ImuContentError),
    /// A fixed-size frame's value no working sensor produces (valid CRC, insane value).
    OutOfRange(ValueOutOfRange),
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
            DecodeError::Content(e) => e.fmt(f),
            DecodeError::OutOfRange(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for DecodeError {}
