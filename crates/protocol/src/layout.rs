//! Wire layout shared by the encoder and the decoder: the header, the CRC trailer and the largest
//! frame. Each frame type's payload layout is in its module under `frames/`. `docs/protocol.md`
//! is the prose version of these; keep them in step.

use crc::{CRC_32_ISCSI, Crc};

use crate::frame_type::FrameType;
use crate::frames::LARGEST_PAYLOAD_LEN;

// The payload constants of the frame types, where they have always been reachable.
pub use crate::frames::airspeed::{
    AIRSPEED_MAX_ABS_PA, AIRSPEED_PAYLOAD_LEN, AIRSPEED_TEMPERATURE_CENTI_C,
};
pub use crate::frames::aux::AUX_PAYLOAD_LEN;
pub use crate::frames::baro::BARO_PAYLOAD_LEN;
pub use crate::frames::imu::{
    COUNT_MAX, COUNT_MIN, COUNTS_PER_FULL_SCALE, IMU_FIXED_LEN, count_in_range, imu_payload_len,
};
pub use crate::frames::mag::MAG_PAYLOAD_LEN;

/// Every frame starts with these two bytes.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];

/// Sync (2) + type (1) + payload length (1) + sequence (2) + device time (4).
pub const HEADER_LEN: usize = 10;

/// CRC-32C trailer.
pub const CRC_LEN: usize = 4;

/// Bytes a frame adds around its payload.
pub const FRAME_OVERHEAD: usize = HEADER_LEN + CRC_LEN;

/// Offset of the type byte from the first sync byte.
pub const TYPE_OFFSET: usize = 2;
/// Offset of the payload length byte from the first sync byte.
pub const LEN_OFFSET: usize = 3;
/// Offset of the 16-bit sequence number (little-endian) from the first sync byte.
pub const SEQ_OFFSET: usize = 4;
/// Offset of the 32-bit device time, µs (little-endian), from the first sync byte.
pub const TIME_OFFSET: usize = 6;

/// Largest payload on the wire, of any frame type: an IMU frame with every channel and
/// temperature present.
pub const MAX_PAYLOAD_LEN: usize = LARGEST_PAYLOAD_LEN;

/// Largest frame on the wire, in bytes (95).
pub const MAX_FRAME_LEN: usize = FRAME_OVERHEAD + MAX_PAYLOAD_LEN;

/// CRC-32C (Castagnoli), computed over the type byte through the end of the payload. A `const`
/// so that the lookup table is built at compile time.
pub(crate) const CRC32C: Crc<u32> = Crc::<u32>::new(&CRC_32_ISCSI);

// The length byte must be able to carry the largest payload.
const _: () = assert!(MAX_PAYLOAD_LEN <= u8::MAX as usize);

/// Whether `len` is a payload length a frame of type `frame_type` can have. Checked from the
/// header alone, so that a corrupt length is rejected before waiting for bytes that may never
/// belong to it.
pub fn payload_len_plausible(frame_type: FrameType, len: usize) -> bool {
    frame_type.payload_len_plausible(len)
}
