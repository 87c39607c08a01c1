//! Frames as the serial line carries them: a sequence number, the device time and the contents
//! of one frame type ([`Payload`]; the types are in `frames/`). Wire layout and encoding:
//! `docs/protocol.md`, `layout.rs` and `codec.rs`.

use crate::frames::Payload;

/// A frame as it travels on the wire: 16-bit sequence (per frame type) and 32-bit device time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Sequence number, counted per frame type; wraps at 2^16.
    pub seq: u16,
    /// Device sample clock at the sample, µs; wraps at 2^32 (about 71.6 min).
    pub device_time_us: u32,
    /// The frame's contents.
    pub payload: Payload,
}

/// A frame handed out by the streaming decoder, with sequence and device time extended to 64 bits
/// (they wrap on the wire).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecodedFrame {
    /// Sequence number of its frame type, extended: increasing within the type (re-based after a
    /// sequence jump, never backwards).
    pub seq: u64,
    /// Device sample clock, µs, extended (re-based after a clock discontinuity, never backwards).
    pub device_time_us: u64,
    /// The frame's contents.
    pub payload: Payload,
}
