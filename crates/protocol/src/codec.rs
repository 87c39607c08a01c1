//! Encoding and decoding of one complete frame: the header and the CRC here, the payload by its
//! frame type's [`SensorFrame`](crate::SensorFrame) implementation. All multi-byte fields are
//! little-endian. Neither direction allocates.

use super::error::{DecodeError, EncodeError};
use super::frame::Frame;
use super::frame_type::FrameType;
use super::layout::{CRC_LEN, CRC32C, FRAME_OVERHEAD, HEADER_LEN, LEN_OFFSET, SYNC, TYPE_OFFSET};
use super::wire::{Reader, Writer};

// Where it has always been reachable.
pub use super::frames::airspeed::airspeed_sane;

impl Frame {
    /// Length of the encoded frame, header and CRC included.
    pub fn encoded_len(&self) -> usize {
        FRAME_OVERHEAD + self.payload.wire_len()
    }
}

/// Encodes `frame` into the start of `out` and returns the number of bytes written.
///
/// Fails if `out` is too short or if the contents are not sane for their frame type
/// ([`SensorFrame::check_sane`](crate::SensorFrame::check_sane)): an IMU channel count above
/// `MAX_CHANNELS` / `MAX_TEMPERATURES`, a gyro/accel count outside -2048..=2047, an airspeed
/// value outside [`airspeed_sane`]. Array entries past the channel counts are not sent.
pub fn encode(frame: &Frame, out: &mut [u8]) -> Result<usize, EncodeError> {
    frame.payload.check_sane()?;
    let payload_len = frame.payload.wire_len();
    let total = FRAME_OVERHEAD + payload_len;
    let available = out.len();
    let out = out.get_mut(..total).ok_or(EncodeError::BufferTooSmall {
        needed: total,
        available,
    })?;

    let mut w = Writer::new(out);
    w.bytes(&SYNC);
    w.u8(frame.payload.frame_type() as u8);
    // Cannot truncate: `wire_len` is at most MAX_PAYLOAD_LEN, which fits a u8 (checked in layout).
    w.u8(payload_len as u8);
    w.u16(frame.seq);
    w.u32(frame.device_time_us);
    frame.payload.encode(&mut w);
    let body_end = total - CRC_LEN;
    debug_assert_eq!(w.written(), body_end, "payload written ≠ its wire_len");
    let crc = CRC32C.checksum(&w.buf()[TYPE_OFFSET..body_end]);
    w.u32(crc);
    Ok(total)
}

/// Total frame length announced by the header at the start of `bytes`, validated as far as the
/// bytes present allow: sync word, frame type, and a payload length plausible for that type.
///
/// Returns `Incomplete` while fewer than 4 bytes are present, so that a decoder can wait for them.
pub fn peek_frame_len(bytes: &[u8]) -> Result<usize, DecodeError> {
    let incomplete = DecodeError::Incomplete { needed: HEADER_LEN };
    match bytes {
        [] => return Err(incomplete),
        [a] if *a == SYNC[0] => return Err(incomplete),
        [a, b, ..] if [*a, *b] == SYNC => {}
        _ => return Err(DecodeError::NoSync),
    }
    let &type_byte = bytes.get(TYPE_OFFSET).ok_or(incomplete)?;
    let frame_type =
        FrameType::from_u8(type_byte).ok_or(DecodeError::UnknownFrameType { value: type_byte })?;
    let len = usize::from(*bytes.get(LEN_OFFSET).ok_or(incomplete)?);
    if !frame_type.payload_len_plausible(len) {
        return Err(DecodeError::BadPayloadLength { frame_type, len });
    }
    Ok(FRAME_OVERHEAD + len)
}

/// Decodes the frame at the start of `bytes` and returns it with the number of bytes it occupies.
/// Bytes after the frame are ignored.
///
/// The order of checks is: header (sync, type, length), CRC, then payload contents (channel
/// counts, 12-bit range, sane airspeed values). A frame is returned only if its CRC matched.
pub fn decode_frame(bytes: &[u8]) -> Result<(Frame, usize), DecodeError> {
    let frame_len = peek_frame_len(bytes)?;
    let incomplete = DecodeError::Incomplete { needed: frame_len };
    let frame = bytes.get(..frame_len).ok_or(incomplete)?;
    // frame_len >= FRAME_OVERHEAD, so the body holds at least the whole header.
    let (body, trailer) = frame.split_at(frame_len - CRC_LEN);
    let received = Reader::new(trailer, incomplete).u32()?;
    let computed = CRC32C.checksum(&body[TYPE_OFFSET..]);
    if received != computed {
        return Err(DecodeError::CrcMismatch { received, computed });
    }

    let mut r = Reader::new(&body[TYPE_OFFSET..], incomplete);
    let type_byte = r.u8()?;
    let _len = r.u8()?;
    let seq = r.u16()?;
    let device_time_us = r.u32()?;
    let frame_type =
        FrameType::from_u8(type_byte).ok_or(DecodeError::UnknownFrameType { value: type_byte })?;
    let payload = frame_type.decode_payload(r.rest())?;
    Ok((
        Frame {
            seq,
            device_time_us,
            payload,
        },
        frame_len,
    ))
}
