//! Streaming decoder: turns an arbitrarily chunked byte stream into frames, resynchronising after
//! garbage, with a fixed-size buffer and no allocation.

use super::codec::decode_frame;
use super::error::DecodeError;
use super::extend::{SeqExtender, TimeExtender};
use super::frame::{DecodedFrame, Frame, FrameType};
use super::layout::{MAX_FRAME_LEN, SYNC};

/// Internal buffer size. Must exceed `MAX_FRAME_LEN` so that, after the complete frames are
/// consumed, room is left for at least one more byte.
const BUF_LEN: usize = 4 * MAX_FRAME_LEN;

/// Counters of a [`Decoder`]. They only ever grow; `Decoder::reset` keeps them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DecoderStats {
    /// Frames handed out.
    pub frames: u64,
    /// Frames handed out, indexed by [`FrameType::index`].
    pub frames_by_type: [u64; FrameType::COUNT],
    /// Candidate frames rejected because the CRC did not match.
    pub crc_errors: u64,
    /// Candidate frames rejected for their contents: unknown type, implausible length, too many
    /// channels, counts outside 12 bits.
    pub malformed: u64,
    /// Frames missing according to the per-type sequence numbers.
    pub lost_frames: u64,
    /// Frames missing, indexed by [`FrameType::index`].
    pub lost_frames_by_type: [u64; FrameType::COUNT],
    /// Bytes discarded while looking for a frame (including the bytes of rejected candidates and
    /// the bytes dropped by [`Decoder::reset`]).
    pub resync_bytes: u64,
}

/// Streaming frame decoder. Feed it bytes as they arrive with [`Decoder::push`].
///
/// After a rejected candidate (bad CRC or malformed) it skips a single byte, the first sync byte,
/// and searches again, so a sync word inside garbage or inside a corrupt frame can never hide a
/// real frame that starts within the bytes it claimed. A real frame is delivered at the latest
/// once `MAX_FRAME_LEN` bytes from its first byte have arrived.
/// The last extended sequence number of each frame type (indexed by [`FrameType::index`]) and
/// the last extended device time. A restarted acquisition continues from the point its previous
/// run saved, so the sequence numbers consumers see never run backwards.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ResumePoint {
    pub seq: [Option<u64>; FrameType::COUNT],
    pub time_us: Option<u64>,
}

#[derive(Debug, Clone)]
pub struct Decoder {
    buf: [u8; BUF_LEN],
    len: usize,
    stats: DecoderStats,
    seq: [SeqExtender; FrameType::COUNT],
    time: TimeExtender,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    pub fn new() -> Self {
        Self {
            buf: [0; BUF_LEN],
            len: 0,
            stats: DecoderStats::default(),
            seq: [SeqExtender::default(); FrameType::COUNT],
            time: TimeExtender::default(),
        }
    }

    /// Consumes `bytes` and calls `on_frame` for every complete, valid frame, in stream order.
    /// Bytes of an incomplete frame are kept for the next call.
    pub fn push(&mut self, mut bytes: &[u8], mut on_frame: impl FnMut(DecodedFrame)) {
        while !bytes.is_empty() {
            let n = (BUF_LEN - self.len).min(bytes.len());
            let (head, rest) = bytes.split_at(n);
            self.buf[self.len..self.len + n].copy_from_slice(head);
            self.len += n;
            bytes = rest;
            self.drain(&mut on_frame);
        }
    }

    /// Counters so far.
    pub fn stats(&self) -> DecoderStats {
        self.stats
    }

    /// Bytes held back as the possible start of a frame.
    pub fn buffered_len(&self) -> usize {
        self.len
    }

    /// Starts afresh after a reconnect: drops buffered bytes (counted in `resync_bytes`). The
    /// sequence numbers go on from the last ones, so that they never run backwards downstream,
    /// and the frames the device sent while it was away are counted lost, from the step of its
    /// sequence number (meaningless only if the device restarted its counter meanwhile).
    /// Counters are kept.
    pub fn reset(&mut self) {
        self.stats.resync_bytes += self.len as u64;
        self.len = 0;
    }

    /// Where the extended sequence numbers (per frame type) and device time stand.
    pub fn resume_point(&self) -> ResumePoint {
        ResumePoint {
            seq: self.seq.map(|s| s.last()),
            time_us: self.time.last(),
        }
    }

    /// Continues the extended numbering of an earlier run (see [`ResumePoint`]).
    pub fn resume_from(&mut self, point: &ResumePoint) {
        for (extender, last) in self.seq.iter_mut().zip(point.seq) {
            if let Some(last) = last {
                extender.resume_from(last);
            }
        }
        if let Some(t) = point.time_us {
            self.time.resume_from(t);
        }
    }

    /// Decodes every complete frame in the buffer and moves the unconsumed tail to the front.
    /// Leaves fewer than `MAX_FRAME_LEN` bytes behind.
    fn drain(&mut self, on_frame: &mut impl FnMut(DecodedFrame)) {
        let mut start = 0;
        loop {
            let pending = &self.buf[start..self.len];
            let Some(offset) = find_sync(pending) else {
                // A trailing first sync byte may be completed by the next push.
                let keep = usize::from(pending.last() == Some(&SYNC[0]));
                let dropped = pending.len() - keep;
                self.stats.resync_bytes += dropped as u64;
                start += dropped;
                break;
            };
            self.stats.resync_bytes += offset as u64;
            start += offset;
            match decode_frame(&self.buf[start..self.len]) {
                Ok((frame, used)) => {
                    start += used;
                    on_frame(self.extend(frame));
                }
                Err(DecodeError::Incomplete { .. }) => break,
                Err(e) => {
                    if e.is_crc() {
                        self.stats.crc_errors += 1;
                    } else {
                        self.stats.malformed += 1;
                    }
                    self.stats.resync_bytes += 1;
                    start += 1;
                }
            }
        }
        self.buf.copy_within(start..self.len, 0);
        self.len -= start;
    }

    fn extend(&mut self, frame: Frame) -> DecodedFrame {
        let i = frame.payload.frame_type().index();
        let (seq, lost) = self.seq[i].extend(frame.seq);
        self.stats.frames += 1;
        self.stats.frames_by_type[i] += 1;
        self.stats.lost_frames += lost;
        self.stats.lost_frames_by_type[i] += lost;
        DecodedFrame {
            seq,
            device_time_us: self.time.extend(frame.device_time_us),
            payload: frame.payload,
        }
    }
}

/// Offset of the first complete sync word in `bytes`.
fn find_sync(bytes: &[u8]) -> Option<usize> {
    bytes.windows(SYNC.len()).position(|w| w == SYNC)
}
