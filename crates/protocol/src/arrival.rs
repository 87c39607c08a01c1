//! Whether a device counter (sequence numbers, device clock) has run ahead of the receive clock.
//!
//! A frame can arrive *later* than the device's counter says it was made — it waited in the kernel
//! while the process was busy, or a whole backlog is read at once after a stall, of which the kernel
//! may have dropped the middle — but it cannot arrive *earlier*. So the comparison is made against
//! an anchor: the frame that arrived earliest relative to the counter. A counter that has moved
//! further since the anchor than the receive clock has is a discontinuity of the device (a
//! restarted or corrupted counter, a clock that jumped), however late the previous frames were.

/// The frame that fixes where the counter stands on the receive clock.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ArrivalAnchor {
    /// Counter value (device units) and receive time (CLOCK_MONOTONIC ns) of the anchor frame.
    at: Option<(u64, u64)>,
}

/// The anchor moves to a frame late by up to this fraction of the anchor's age: rate errors (a
/// learnt period, the device's crystal against CLOCK_MONOTONIC) make frames look ever later, and
/// an anchor left behind would make a real jump ever harder to see. A backlog makes frames late by
/// far more than this over the seconds it lasts, so it never drags the anchor with it.
const DRIFT_DIVISOR: u64 = 50;

impl ArrivalAnchor {
    /// How far (ns; negative when late) a frame whose counter reads `device` arrived ahead of what
    /// the anchor predicts, with `unit_ns` nanoseconds per counter unit. `None` before the first
    /// frame.
    pub fn ahead_ns(&self, device: u64, unit_ns: u64, rx_ns: u64) -> Option<i128> {
        let (d0, r0) = self.at?;
        let counted = (i128::from(device) - i128::from(d0)) * i128::from(unit_ns);
        Some(counted - (i128::from(rx_ns) - i128::from(r0)))
    }

    /// Receive time elapsed since the anchor frame, ns (0 before the first frame).
    pub fn age_ns(&self, rx_ns: u64) -> u64 {
        self.at.map_or(0, |(_, r0)| rx_ns.saturating_sub(r0))
    }

    /// Takes a frame the caller has accepted (after any re-base): it becomes the anchor when it
    /// arrived no later than the anchor predicts, or late by a small fraction of the anchor's age.
    pub fn observe(&mut self, device: u64, unit_ns: u64, rx_ns: u64) {
        let drift = i128::from(self.age_ns(rx_ns) / DRIFT_DIVISOR);
        match self.ahead_ns(device, unit_ns, rx_ns) {
            Some(ahead) if ahead < -drift => {}
            _ => self.at = Some((device, rx_ns)),
        }
    }

    /// Whether the anchor is set.
    pub fn is_set(&self) -> bool {
        self.at.is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn late_frames_keep_the_anchor_and_a_jump_shows_ahead() {
        let mut a = ArrivalAnchor::default();
        assert_eq!(a.ahead_ns(5, MS, 0), None);
        a.observe(100, MS, 1_000 * MS);
        // 300 frames of a backlog read 3 s late: late, the anchor stays.
        assert_eq!(
            a.ahead_ns(400, MS, 4_000 * MS),
            Some(-2_700 * i128::from(MS))
        );
        a.observe(400, MS, 4_000 * MS);
        assert_eq!(a.age_ns(4_000 * MS), 3_000 * MS);
        // The frames after the dropped middle arrive on time: not ahead.
        assert_eq!(a.ahead_ns(3_100, MS, 4_001 * MS), Some(-i128::from(MS)));
        // A counter 30 000 ahead is.
        assert_eq!(
            a.ahead_ns(30_100, MS, 1_001 * MS),
            Some(29_999 * i128::from(MS))
        );
    }

    #[test]
    fn a_slightly_slow_counter_moves_the_anchor_with_it() {
        let mut a = ArrivalAnchor::default();
        a.observe(0, MS, 0);
        // 0.5 % slow over 10 s: 50 ms late, within 2 % of the anchor's age.
        a.observe(9_950, MS, 10_000 * MS);
        assert_eq!(a.age_ns(10_000 * MS), 0);
    }
}
