//! Little-endian field access for payloads: the [`Writer`] a frame type encodes into and the
//! [`Reader`] it decodes from. Neither allocates; the reader never reads past its bytes.

use crate::error::DecodeError;
use crate::frame_type::FrameType;

/// Sequential writer into a buffer already sized to the frame (the codec sizes it from
/// [`crate::SensorFrame::wire_len`], so writing exactly that many bytes always fits).
pub struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl<'a> Writer<'a> {
    pub(crate) fn new(buf: &'a mut [u8]) -> Self {
        Self { buf, pos: 0 }
    }

    /// Bytes written so far.
    pub(crate) fn written(&self) -> usize {
        self.pos
    }

    /// The whole buffer, for the CRC over what was written.
    pub(crate) fn buf(&self) -> &[u8] {
        self.buf
    }

    /// Appends raw bytes.
    pub fn bytes(&mut self, b: &[u8]) {
        self.buf[self.pos..self.pos + b.len()].copy_from_slice(b);
        self.pos += b.len();
    }
    /// Appends a `u8`.
    pub fn u8(&mut self, v: u8) {
        self.bytes(&[v]);
    }
    /// Appends a `u16`, little-endian.
    pub fn u16(&mut self, v: u16) {
        self.bytes(&v.to_le_bytes());
    }
    /// Appends an `i16`, little-endian.
    pub fn i16(&mut self, v: i16) {
        self.bytes(&v.to_le_bytes());
    }
    /// Appends a `u32`, little-endian.
    pub fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }
    /// Appends an `i32`, little-endian.
    pub fn i32(&mut self, v: i32) {
        self.bytes(&v.to_le_bytes());
    }
    /// Appends an `f32`, little-endian.
    pub fn f32(&mut self, v: f32) {
        self.bytes(&v.to_le_bytes());
    }
}

/// Sequential little-endian reader; a read past the end returns the error the reader was made
/// with instead of panicking.
pub struct Reader<'a> {
    buf: &'a [u8],
    short: DecodeError,
}

impl<'a> Reader<'a> {
    /// A reader over `buf` that answers `short` to a read past its end.
    pub(crate) fn new(buf: &'a [u8], short: DecodeError) -> Self {
        Self { buf, short }
    }

    /// A reader over the payload of a `frame_type` frame. A short read cannot happen once the
    /// header's length has passed [`crate::SensorFrame::len_plausible`]; should it, the payload
    /// length was wrong for its contents, and that is the error.
    pub fn payload(frame_type: FrameType, payload: &'a [u8]) -> Self {
        Self::new(payload, Self::bad_length(frame_type, payload))
    }

    /// The error of a `frame_type` payload whose length does not fit its contents.
    pub fn bad_length(frame_type: FrameType, payload: &[u8]) -> DecodeError {
        DecodeError::BadPayloadLength {
            frame_type,
            len: payload.len(),
        }
    }

    /// The bytes not read yet.
    pub(crate) fn rest(&self) -> &'a [u8] {
        self.buf
    }

    fn take<const N: usize>(&mut self) -> Result<[u8; N], DecodeError> {
        let (head, rest) = self.buf.split_at_checked(N).ok_or(self.short)?;
        self.buf = rest;
        head.try_into().map_err(|_| self.short)
    }
    /// Reads a `u8`.
    pub fn u8(&mut self) -> Result<u8, DecodeError> {
        self.take::<1>().map(|[b]| b)
    }
    /// Reads a little-endian `u16`.
    pub fn u16(&mut self) -> Result<u16, DecodeError> {
        self.take().map(u16::from_le_bytes)
    }
    /// Reads a little-endian `i16`.
    pub fn i16(&mut self) -> Result<i16, DecodeError> {
        self.take().map(i16::from_le_bytes)
    }
    /// Reads a little-endian `u32`.
    pub fn u32(&mut self) -> Result<u32, DecodeError> {
        self.take().map(u32::from_le_bytes)
    }
    /// Reads a little-endian `i32`.
    pub fn i32(&mut self) -> Result<i32, DecodeError> {
        self.take().map(i32::from_le_bytes)
    }
    /// Reads a little-endian `f32`.
    pub fn f32(&mut self) -> Result<f32, DecodeError> {
        self.take().map(f32::from_le_bytes)
    }
}
