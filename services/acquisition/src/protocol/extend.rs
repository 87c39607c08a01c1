//! Extension of the wrapping wire counters (16-bit sequence, 32-bit microsecond clock) to 64 bits.

/// Extends one frame type's 16-bit sequence number and counts the frames missing in between.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SeqExtender {
    last: Option<u64>,
    /// The next step is taken without counting losses (after a resume).
    uncounted: bool,
}

impl SeqExtender {
    /// Extended sequence number of `seq` and the number of frames lost since the previous one.
    ///
    /// The first call sets the reference (extended = wire value, nothing lost). After that a step
    /// of k (mod 2^16, 1 ≤ k ≤ 65535) from the previous number means k − 1 frames were lost. A
    /// repeated number (k = 0) is taken as a repeat, not as 65535 losses: it loses nothing and
    /// keeps the extended value.
    pub fn extend(&mut self, seq: u16) -> (u64, u64) {
        let Some(last) = self.last else {
            self.last = Some(u64::from(seq));
            return (u64::from(seq), 0);
        };
        // Truncation intended: the step is the difference of the low 16 bits.
        let step = seq.wrapping_sub(last as u16);
        if step == 0 {
            return (last, 0);
        }
        let extended = last.wrapping_add(u64::from(step));
        self.last = Some(extended);
        if std::mem::take(&mut self.uncounted) {
            return (extended, 0);
        }
        (extended, u64::from(step) - 1)
    }

    /// Continues after `last`, the extended number of a frame published earlier by a previous run
    /// of this process, so that the numbers never run backwards downstream. The step to the next
    /// frame is not counted as lost: `last` may be up to a second old, and the frames in between
    /// were published by that run.
    pub fn resume_from(&mut self, last: u64) {
        self.last = Some(last);
        self.uncounted = true;
    }

    /// The extended number of the last frame.
    pub fn last(&self) -> Option<u64> {
        self.last
    }
}

/// Extends the device's 32-bit microsecond clock (wraps every 2^32 µs ≈ 71.6 min) to 64 bits.
///
/// All frame types share the one device clock, so one extender serves them all. Each time is
/// placed at the 64-bit value congruent to it (mod 2^32) that lies closest to the previous
/// frame's time, i.e. within −2^31..2^31 µs (±35.8 min). Wraps are thus followed as long as
/// consecutive frames are less than 35.8 min apart, and frames of different types may arrive
/// slightly out of time order without being mistaken for a wrap.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct TimeExtender {
    /// Signed so that a frame stamped just before the first one stays congruent to its wire value.
    last: Option<i64>,
}

impl TimeExtender {
    /// Extended device time of `time_us`. The first call sets the reference (extended = wire
    /// value). A time that would precede zero (stamped before the first frame and before the
    /// device clock's first wrap) is reported as 0.
    pub fn extend(&mut self, time_us: u32) -> u64 {
        let extended = match self.last {
            None => i64::from(time_us),
            Some(last) => {
                // Truncations intended: the step is the signed difference of the low 32 bits.
                let step = time_us.wrapping_sub(last as u32) as i32;
                last.saturating_add(i64::from(step))
            }
        };
        self.last = Some(extended);
        u64::try_from(extended).unwrap_or(0)
    }

    /// Continues from `last_us`, the extended time of a frame published earlier.
    pub fn resume_from(&mut self, last_us: u64) {
        self.last = i64::try_from(last_us).ok();
    }

    /// The extended time of the last frame, µs.
    pub fn last(&self) -> Option<u64> {
        self.last.and_then(|t| u64::try_from(t).ok())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sequence_gaps_across_the_wrap() {
        let mut s = SeqExtender::default();
        assert_eq!(s.extend(65534), (65534, 0));
        assert_eq!(s.extend(65535), (65535, 0));
        assert_eq!(s.extend(0), (65536, 0));
        assert_eq!(s.extend(3), (65539, 2));
        // 65535 steps forward: 65534 lost.
        assert_eq!(s.extend(2), (65539 + 65535, 65534));
        assert_eq!(s.extend(2), (65539 + 65535, 0));
    }

    #[test]
    fn a_resume_continues_forward_without_counting_the_step() {
        // A previous run published up to 200_005 (wire 200_005 mod 2^16 = 3_397).
        let mut r = SeqExtender::default();
        r.resume_from(200_005);
        assert_eq!(r.last(), Some(200_005));
        assert_eq!(r.extend(3_400), (200_008, 0));
        assert_eq!(r.extend(3_402), (200_010, 1));
        let mut t = TimeExtender::default();
        t.resume_from(5 << 32);
        assert_eq!(t.extend(10), (5 << 32) + 10);
        assert_eq!(t.last(), Some((5 << 32) + 10));
    }

    #[test]
    fn time_follows_wraps_and_small_reversals() {
        let mut t = TimeExtender::default();
        let wrap = 1u64 << 32;
        assert_eq!(t.extend(u32::MAX - 10), wrap - 11);
        // A frame of another type stamped slightly earlier.
        assert_eq!(t.extend(u32::MAX - 20), wrap - 21);
        assert_eq!(t.extend(5), wrap + 5);
        // Largest forward step that is still taken as forward: 2^31 - 1.
        assert_eq!(t.extend(5 + (1 << 31) - 1), wrap + 5 + (1 << 31) - 1);
        // A further 2^31 (wire 4, after wrapping) is taken as 2^31 backwards.
        assert_eq!(t.extend(4), wrap + 4);
    }

    #[test]
    fn time_before_the_first_frame_clamps_at_zero_but_stays_congruent() {
        let mut t = TimeExtender::default();
        assert_eq!(t.extend(5), 5);
        assert_eq!(t.extend(u32::MAX - 2), 0); // 8 µs before the first frame: −3
        assert_eq!(t.extend(6), 6);
    }
}
