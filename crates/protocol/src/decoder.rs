//! Streaming decoder: turns an arbitrarily chunked byte stream into frames, resynchronising after
//! garbage, with a fixed-size buffer and no allocation. Each frame is classified by its sequence
//! number (new, duplicate, late, jump: [`super::seq_extend`]) and only new frames are handed out,
//! with sequence number and device time extended to 64 bits ([`super::time_extend`]).

use super::codec::decode_frame;
use super::continuity::Continuity;
use super::error::DecodeError;
use super::frame::{DecodedFrame, Frame};
use super::frame_type::FrameType;
use super::layout::{FRAME_OVERHEAD, LEN_OFFSET, MAX_FRAME_LEN, SYNC};
use super::resume_point::{ResumeError, ResumePoint};
use super::seq_extend::{SeqExtender, SeqVerdict};
use super::time_extend::TimeExtender;

/// Internal buffer size. Must exceed `MAX_FRAME_LEN` so that, after the complete frames are
/// consumed, room is left for at least one more byte.
const BUF_LEN: usize = 4 * MAX_FRAME_LEN;

/// Counters of a [`Decoder`]. They only ever grow, but for `lost_frames`, from which a late frame
/// is taken back out; `Decoder::reset` keeps them.
///
/// When the first frame received of each type has its lowest number and no sequence jump occurs,
/// `frames` + `late` + `lost_frames` = the numbers from each type's first frame to its newest
/// (summed over the types), and `duplicates` counts the extra copies, whatever the order of
/// arrival within the window of [`super::seq_window::WINDOW`] numbers.
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
    /// Frames missing according to the per-type sequence numbers (not yet arrived).
    pub lost_frames: u64,
    /// Frames missing, indexed by [`FrameType::index`].
    pub lost_frames_by_type: [u64; FrameType::COUNT],
    /// Valid frames whose sequence number was received before: not handed out.
    pub duplicates: u64,
    /// Valid frames behind the newest of their type, not received before (reordered), or too far
    /// behind to tell: not handed out, and no longer counted lost.
    pub late: u64,
    /// Sequence jumps: a number implausibly far ahead of the receive clock, or too far behind to
    /// be a late frame and continued by the next frame of its type (a counter that restarted; a
    /// single frame that far behind is counted `late`). The numbering was re-based; nothing
    /// counted lost.
    pub seq_jumps: u64,
    /// Device-time discontinuities re-based on the receive clock.
    pub time_rebases: u64,
    /// Resume points (or their parts) ignored: out of bounds, or too far from the first frame's
    /// wire values.
    pub resume_rejected: u64,
    /// Bytes discarded while looking for a frame (including the bytes of rejected candidates and
    /// the bytes dropped by [`Decoder::reset`]).
    pub resync_bytes: u64,
    /// Bytes of valid frames not handed out (duplicates, late frames).
    pub withheld_bytes: u64,
    /// Bytes pushed into the decoder: everything read from the line.
    pub bytes: u64,
    /// Why the last bytes that could not be decoded were refused: [`DecodeError::NoSync`] when
    /// bytes without a sync word were skipped (outside a rejected candidate's own bytes), else the
    /// rejected candidate's error. `None` until something was refused.
    pub last_error: Option<DecodeError>,
}

impl DecoderStats {
    /// Frames with a valid CRC and sane content: handed out, or withheld as duplicate or late.
    pub fn valid_frames(&self) -> u64 {
        self.frames + self.duplicates + self.late
    }
}

/// Streaming frame decoder. Feed it bytes as they arrive with [`Decoder::push`].
///
/// After a rejected candidate (bad CRC or malformed) it skips a single byte, the first sync byte,
/// and searches again, so a sync word inside garbage or inside a corrupt frame can never hide a
/// real frame that starts within the bytes it claimed. A real frame is delivered at the latest
/// once `MAX_FRAME_LEN` bytes from its first byte have arrived.
#[derive(Debug, Clone)]
pub struct Decoder {
    buf: [u8; BUF_LEN],
    len: usize,
    stats: DecoderStats,
    seq: [SeqExtender; FrameType::COUNT],
    time: TimeExtender,
    /// Bytes after the first byte of the last rejected candidate that it claimed as its own:
    /// skipping them is part of that rejection, not a missing sync word.
    reject_cover: usize,
}

impl Default for Decoder {
    fn default() -> Self {
        Self::new()
    }
}

impl Decoder {
    /// An empty decoder: no buffered bytes, zero counters, no numbering yet (the first frame of
    /// each type starts its sequence; the first frame of any type starts the device time).
    pub fn new() -> Self {
        Self {
            buf: [0; BUF_LEN],
            len: 0,
            stats: DecoderStats::default(),
            seq: [SeqExtender::default(); FrameType::COUNT],
            time: TimeExtender::default(),
            reject_cover: 0,
        }
    }

    /// Consumes `bytes`, received at `rx_ns` (CLOCK_MONOTONIC, when the read returned them), and
    /// calls `on_frame` for every complete, valid, new frame, in stream order. Bytes of an
    /// incomplete frame are kept for the next call.
    pub fn push(&mut self, mut bytes: &[u8], rx_ns: u64, mut on_frame: impl FnMut(DecodedFrame)) {
        self.stats.bytes += bytes.len() as u64;
        while !bytes.is_empty() {
            let n = (BUF_LEN - self.len).min(bytes.len());
            let (head, rest) = bytes.split_at(n);
            self.buf[self.len..self.len + n].copy_from_slice(head);
            self.len += n;
            bytes = rest;
            self.drain(rx_ns, &mut on_frame);
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
    /// sequence number, which the receive clock confirms (a device that restarted its counter
    /// meanwhile shows as a sequence jump). Counters are kept.
    pub fn reset(&mut self) {
        self.stats.resync_bytes += self.len as u64;
        self.len = 0;
        for s in &mut self.seq {
            s.reconnected();
        }
    }

    /// Where the extended sequence numbers (per frame type) and device time stand.
    pub fn resume_point(&self) -> ResumePoint {
        ResumePoint {
            seq: self.seq.map(|s| s.last()),
            seq_wire: self.seq.map(|s| s.last_wire()),
            time_us: self.time.last(),
            time_wire: self.time.last_wire(),
        }
    }

    /// Continues the extended numbering of an earlier run (see [`ResumePoint`]). A point with a
    /// value out of bounds is rejected whole (counted in `resume_rejected`, nothing changes); the
    /// parts of a good one apply to the first frame of each type and the first frame's time, each
    /// ignored (and counted) when the device's first value is not a plausible step ahead of it.
    pub fn resume_from(&mut self, point: &ResumePoint) -> Result<(), ResumeError> {
        if let Err(e) = point.check() {
            self.stats.resume_rejected += 1;
            return Err(e);
        }
        for ((extender, last), wire) in self.seq.iter_mut().zip(point.seq).zip(point.seq_wire) {
            if let Some(last) = last {
                extender.resume_from(last, wire);
            }
        }
        if let Some(t) = point.time_us {
            self.time.resume_from(t, point.time_wire);
        }
        Ok(())
    }

    /// Decodes every complete frame in the buffer and moves the unconsumed tail to the front.
    /// Leaves fewer than `MAX_FRAME_LEN` bytes behind.
    fn drain(&mut self, rx_ns: u64, on_frame: &mut impl FnMut(DecodedFrame)) {
        let mut start = 0;
        loop {
            let pending = &self.buf[start..self.len];
            let Some(offset) = find_sync(pending) else {
                // A trailing first sync byte may be completed by the next push.
                let keep = usize::from(pending.last() == Some(&SYNC[0]));
                let dropped = pending.len() - keep;
                self.skipped(dropped);
                start += dropped;
                break;
            };
            self.skipped(offset);
            start += offset;
            match decode_frame(&self.buf[start..self.len]) {
                Ok((frame, used)) => {
                    start += used;
                    self.reject_cover = 0;
                    if let Some(decoded) = self.classify(frame, rx_ns) {
                        on_frame(decoded);
                    } else {
                        self.stats.withheld_bytes += used as u64;
                    }
                }
                Err(DecodeError::Incomplete { .. }) => break,
                Err(e) => {
                    if e.is_crc() {
                        self.stats.crc_errors += 1;
                    } else {
                        self.stats.malformed += 1;
                    }
                    self.stats.last_error = Some(e);
                    // The candidate's bytes after its first: the whole length its header
                    // announces, whatever its type (an unknown type is still a frame's worth).
                    let claimed = if start + LEN_OFFSET < self.len {
                        FRAME_OVERHEAD + usize::from(self.buf[start + LEN_OFFSET])
                    } else {
                        LEN_OFFSET + 1
                    };
                    self.reject_cover = claimed - 1;
                    self.stats.resync_bytes += 1;
                    start += 1;
                }
            }
        }
        self.buf.copy_within(start..self.len, 0);
        self.len -= start;
    }

    /// Counts `n` bytes skipped while searching for a sync word; those beyond the last rejected
    /// candidate's own bytes mean the line carries something that is not frames.
    fn skipped(&mut self, n: usize) {
        self.stats.resync_bytes += n as u64;
        if n > self.reject_cover {
            self.stats.last_error = Some(DecodeError::NoSync);
        }
        self.reject_cover = self.reject_cover.saturating_sub(n);
    }

    /// The frame as it is handed out, or `None` for a duplicate or late frame; counts either way.
    fn classify(&mut self, frame: Frame, rx_ns: u64) -> Option<DecodedFrame> {
        let i = frame.payload.frame_type().index();
        let stats = &mut self.stats;
        let (seq, lost, continuity) = match self.seq[i].extend(frame.seq, rx_ns) {
            SeqVerdict::New {
                seq,
                lost,
                continuity,
            } => (seq, lost, continuity),
            SeqVerdict::Duplicate => {
                stats.duplicates += 1;
                return None;
            }
            SeqVerdict::Late { recovered } => {
                stats.late += 1;
                if recovered {
                    stats.lost_frames = stats.lost_frames.saturating_sub(1);
                    stats.lost_frames_by_type[i] = stats.lost_frames_by_type[i].saturating_sub(1);
                }
                return None;
            }
        };
        stats.frames += 1;
        stats.frames_by_type[i] += 1;
        stats.lost_frames += lost;
        stats.lost_frames_by_type[i] += lost;
        count_continuity(continuity, &mut stats.seq_jumps, &mut stats.resume_rejected);
        let time = self.time.extend(frame.device_time_us, rx_ns);
        count_continuity(
            time.continuity,
            &mut stats.time_rebases,
            &mut stats.resume_rejected,
        );
        Some(DecodedFrame {
            seq,
            device_time_us: time.time_us,
            payload: frame.payload,
        })
    }
}

/// Counts a re-base or an ignored resume point.
fn count_continuity(continuity: Continuity, rebases: &mut u64, resume_rejected: &mut u64) {
    match continuity {
        Continuity::Continued => {}
        Continuity::Rebased => *rebases += 1,
        Continuity::ResumeIgnored => *resume_rejected += 1,
    }
}

/// Offset of the first complete sync word in `bytes`.
fn find_sync(bytes: &[u8]) -> Option<usize> {
    bytes.windows(SYNC.len()).position(|w| w == SYNC)
}
