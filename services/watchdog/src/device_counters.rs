//! The serial device's counters as acquisition's heartbeats carry them, and their sum over
//! acquisition's restarts.

use ipc_types::Health;

/// The serial device's counters, as acquisition reports them (see the decoder's `DecoderStats`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct DeviceCounters {
    /// Serial frames with a bad CRC.
    pub crc_errors: u64,
    /// Valid CRC, malformed content.
    pub malformed_frames: u64,
    /// Frames missing from the device's sequence.
    pub lost_frames: u64,
    /// Repeated sequence numbers, not published.
    pub duplicate_frames: u64,
    /// Reordered frames that came after a later one, not published, not lost.
    pub late_frames: u64,
    /// Device sequence-counter discontinuities.
    pub seq_jumps: u64,
    /// Device-clock discontinuities.
    pub time_rebases: u64,
    /// Bytes skipped while resynchronising.
    pub resync_bytes: u64,
    /// Times the device was reopened.
    pub reconnects: u64,
    /// Bytes read from the device.
    pub bytes_received: u64,
    /// Frames with a valid CRC and sane content (published, or withheld as duplicate or late).
    pub valid_frames: u64,
    /// [`ipc_types::LinkError`] as u8 of the last refusal.
    pub last_decode_error: u8,
}

impl DeviceCounters {
    /// The counters a heartbeat of acquisition carries.
    pub fn from_heartbeat(h: &Health) -> Self {
        Self {
            crc_errors: h.crc_errors,
            malformed_frames: h.malformed,
            lost_frames: h.lost,
            duplicate_frames: h.duplicates,
            late_frames: h.late,
            seq_jumps: h.seq_jumps,
            time_rebases: h.time_rebases,
            resync_bytes: h.resync_bytes,
            reconnects: h.reconnects,
            bytes_received: h.bytes_received,
            valid_frames: h.valid_frames,
            last_decode_error: h.last_decode_error,
        }
    }

    /// The sum of two processes' counters; the last refusal is `o`'s (the later process) when it
    /// has one.
    pub fn plus(&self, o: &Self) -> Self {
        Self {
            crc_errors: self.crc_errors + o.crc_errors,
            malformed_frames: self.malformed_frames + o.malformed_frames,
            lost_frames: self.lost_frames + o.lost_frames,
            duplicate_frames: self.duplicate_frames + o.duplicate_frames,
            late_frames: self.late_frames + o.late_frames,
            seq_jumps: self.seq_jumps + o.seq_jumps,
            time_rebases: self.time_rebases + o.time_rebases,
            resync_bytes: self.resync_bytes + o.resync_bytes,
            reconnects: self.reconnects + o.reconnects,
            bytes_received: self.bytes_received + o.bytes_received,
            valid_frames: self.valid_frames + o.valid_frames,
            last_decode_error: if o.last_decode_error != 0 {
                o.last_decode_error
            } else {
                self.last_decode_error
            },
        }
    }
}
