//! The device's 32-bit microsecond clock (wraps every 2^32 µs ≈ 71.6 min) extended to 64 bits, with
//! its discontinuities re-based.
//!
//! All frame types share the one device clock, so one extender serves them all. Each time is
//! placed at the 64-bit value congruent to it (mod 2^32) closest to the previous frame's, i.e. the
//! signed 32-bit difference of the wire times is added: wraps are followed, and frames of different
//! types may arrive slightly out of time order (a small backward step stays one).
//!
//! A **discontinuity** — the device's clock stepping back by more than [`TOLERANCE_US`], or running
//! ahead of the receive clock by more than that (see [`crate::arrival`]; checked once the
//! receive clock has run for [`WARMUP_NS`] after the first frame, as the first reads may be a
//! backlog), or a time that would fall before zero — is **re-based**: the extended time continues
//! from the previous frame's by the receive-clock time elapsed between them (at least 1 µs, as the
//! frames of one read share its receive time), and later frames follow on the new base. The
//! extended time is never clamped and never jumps.
//!
//! The tolerance, 0.5 s: frame types stamped out of order differ by at most a baro period (20 ms);
//! frames arrive late (never early) by the read scheduling, milliseconds, or a backlog; a learnt
//! anchor drifts by rate errors of a few per mille of its age (an extra 1/16 of the age is
//! allowed). 0.5 s is well above all of these and far below a clock that restarted or a time field
//! that was corrupted.

use super::arrival::ArrivalAnchor;
use super::continuity::Continuity;
use super::frame_period::WARMUP_NS;

/// Largest backward step, and largest lead over the receive clock, that is not a discontinuity, µs.
pub const TOLERANCE_US: i64 = 500_000;
/// Plus this fraction of the anchor's age for the lead over the receive clock.
const SLACK_AGE_DIVISOR: u64 = 16;
/// Largest step from a resume point to the first frame's time that continues the point, µs: a
/// restarted acquisition is back within seconds; 10 minutes covers any restart backoff.
pub const RESUME_MAX_STEP_US: i64 = 600_000_000;

const NS_PER_US: u64 = 1_000;

/// One frame's extended device time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExtendedTime {
    /// Device time extended to 64 bits, µs.
    pub time_us: u64,
    /// Whether it continued the previous time, was re-based, or ignored the resume point.
    pub continuity: Continuity,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct LastTime {
    time_us: u64,
    wire: u32,
    rx_ns: u64,
}

/// The device clock's extension to 64 bits, shared by all frame types (see the module
/// documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TimeExtender {
    last: Option<LastTime>,
    first_rx_ns: Option<u64>,
    /// Extended time of the last frame a previous run published and its wire time (when known),
    /// until the first frame.
    resume: Option<(u64, Option<u32>)>,
    /// In µs of extended time.
    anchor: ArrivalAnchor,
}

impl TimeExtender {
    /// Extended device time of a frame stamped `wire` µs, received at `rx_ns` (CLOCK_MONOTONIC).
    /// The first frame sets the reference (extended = wire value, or the resume point plus the
    /// step to it).
    pub fn extend(&mut self, wire: u32, rx_ns: u64) -> ExtendedTime {
        let Some(last) = self.last else {
            return self.first(wire, rx_ns);
        };
        // Truncation intended: the signed 32-bit difference of the wire times.
        let step = i64::from(wire.wrapping_sub(last.wire) as i32);
        let candidate = i128::from(last.time_us) + i128::from(step);
        let continued = u64::try_from(candidate)
            .ok()
            .filter(|&t| step >= -TOLERANCE_US && !self.runs_ahead(t, rx_ns));
        let (time_us, continuity) = match continued {
            Some(t) => (t, Continuity::Continued),
            None => {
                // At least 1 µs: the frames of one read share its receive time, and a re-based
                // time must still advance past the previous frame's.
                let elapsed_us = (rx_ns.saturating_sub(last.rx_ns) / NS_PER_US).max(1);
                (last.time_us.saturating_add(elapsed_us), Continuity::Rebased)
            }
        };
        self.accept(time_us, wire, rx_ns);
        ExtendedTime {
            time_us,
            continuity,
        }
    }

    /// Continues from `last_us`, the extended time of a frame published by a previous run. The
    /// first frame continues it when its wire time lies −[`TOLERANCE_US`]..=[`RESUME_MAX_STEP_US`]
    /// from `last_us`'s; otherwise the point is ignored ([`Continuity::ResumeIgnored`]).
    /// `last_wire`: the wire time `last_us` was given to (after a re-base its low bits are not
    /// it).
    pub fn resume_from(&mut self, last_us: u64, last_wire: Option<u32>) {
        *self = Self {
            resume: Some((last_us, last_wire)),
            ..Self::default()
        };
    }

    /// The extended time of the last frame, µs (before the first, the resume point's).
    pub fn last(&self) -> Option<u64> {
        self.last.map(|l| l.time_us).or(self.resume.map(|r| r.0))
    }

    /// The wire time of the last frame (before the first, the resume point's).
    pub fn last_wire(&self) -> Option<u32> {
        self.last.map(|l| l.wire).or(self.resume.and_then(|r| r.1))
    }

    fn first(&mut self, wire: u32, rx_ns: u64) -> ExtendedTime {
        let resumed = self.resume.take().map(|(point, point_wire)| {
            // Truncation intended: the signed 32-bit difference to the point's wire time (its
            // low bits when the wire time was not saved).
            let step = i64::from(wire.wrapping_sub(point_wire.unwrap_or(point as u32)) as i32);
            let t = i128::from(point) + i128::from(step);
            u64::try_from(t)
                .ok()
                .filter(|_| (-TOLERANCE_US..=RESUME_MAX_STEP_US).contains(&step))
        });
        let (time_us, continuity) = match resumed {
            Some(Some(t)) => (t, Continuity::Continued),
            Some(None) => (u64::from(wire), Continuity::ResumeIgnored),
            None => (u64::from(wire), Continuity::Continued),
        };
        self.first_rx_ns = Some(rx_ns);
        self.accept(time_us, wire, rx_ns);
        ExtendedTime {
            time_us,
            continuity,
        }
    }

    fn accept(&mut self, time_us: u64, wire: u32, rx_ns: u64) {
        self.last = Some(LastTime {
            time_us,
            wire,
            rx_ns,
        });
        self.anchor.observe(time_us, NS_PER_US, rx_ns);
    }

    /// Whether the time `t` µs runs implausibly far ahead of the receive clock (not during the
    /// warm-up).
    fn runs_ahead(&self, t: u64, rx_ns: u64) -> bool {
        let warm = self
            .first_rx_ns
            .is_some_and(|first| rx_ns.saturating_sub(first) >= WARMUP_NS);
        let slack =
            TOLERANCE_US.unsigned_abs() * NS_PER_US + self.anchor.age_ns(rx_ns) / SLACK_AGE_DIVISOR;
        warm && self
            .anchor
            .ahead_ns(t, NS_PER_US, rx_ns)
            .is_some_and(|ahead| ahead > i128::from(slack))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn continued(time_us: u64) -> ExtendedTime {
        ExtendedTime {
            time_us,
            continuity: Continuity::Continued,
        }
    }

    #[test]
    fn follows_wraps_and_small_reversals() {
        let mut t = TimeExtender::default();
        let wrap = 1u64 << 32;
        assert_eq!(t.extend(u32::MAX - 10, 0), continued(wrap - 11));
        // A frame of another type stamped slightly earlier.
        assert_eq!(t.extend(u32::MAX - 20, 0), continued(wrap - 21));
        assert_eq!(t.extend(5, 0), continued(wrap + 5));
        // Largest forward step that is still taken as forward (during the warm-up): 2^31 - 1.
        assert_eq!(
            t.extend(5 + (1 << 31) - 1, 0),
            continued(wrap + 5 + (1 << 31) - 1)
        );
    }

    #[test]
    fn a_jump_forward_and_a_jump_back_are_re_based_on_the_receive_clock() {
        let mut t = TimeExtender::default();
        let mut wire = 1_000u32;
        for k in 0..2_000u64 {
            assert_eq!(t.extend(wire, k * MS), continued(1_000 + k * 1_000));
            wire += 1_000;
        }
        let last = 1_000 + 1_999 * 1_000;
        // +600 s on the device, 1 ms on the receive clock.
        wire += 600_000_000;
        let e = t.extend(wire, 2_000 * MS);
        assert_eq!(e.continuity, Continuity::Rebased);
        assert_eq!(e.time_us, last + 1_000);
        wire += 1_000;
        assert_eq!(t.extend(wire, 2_001 * MS), continued(last + 2_000));
        // +2^31 + 1 µs reads as 2^31 − 1 µs backwards.
        wire = wire.wrapping_add((1 << 31) + 1);
        let e = t.extend(wire, 2_003 * MS);
        assert_eq!(e.continuity, Continuity::Rebased);
        assert_eq!(e.time_us, last + 4_000);
        wire = wire.wrapping_add(1_000);
        assert_eq!(t.extend(wire, 2_004 * MS), continued(last + 5_000));
    }

    #[test]
    fn a_jump_within_one_read_still_advances() {
        let mut t = TimeExtender::default();
        for k in 0..2_000u64 {
            t.extend((k * 1_000) as u32, k * MS);
        }
        // The jumped frame came in the same read as the one before it.
        let e = t.extend(2_000_000 + 600_000_000, 1_999 * MS);
        assert_eq!(e.continuity, Continuity::Rebased);
        assert_eq!(e.time_us, 1_999_000 + 1);
    }

    #[test]
    fn a_frame_stamped_before_zero_is_re_based_not_clamped() {
        let mut t = TimeExtender::default();
        assert_eq!(t.extend(5, 0), continued(5));
        let e = t.extend(u32::MAX - 2, 7_000); // 8 µs before the first frame: −3
        assert_eq!(
            e,
            ExtendedTime {
                time_us: 12,
                continuity: Continuity::Rebased
            }
        );
        assert_eq!(t.extend(6, 8_000), continued(21));
    }

    #[test]
    fn a_backlog_then_its_dropped_middle_is_not_a_discontinuity() {
        let mut t = TimeExtender::default();
        for k in 0..3_000u64 {
            t.extend((k * 1_000) as u32, k * MS);
        }
        // Stalled 3 s: device times 3.0..3.5 s read at 6 s, 3.5..6 s dropped, then on time.
        for k in 3_000..3_500u64 {
            assert_eq!(
                t.extend((k * 1_000) as u32, 6_000 * MS),
                continued(k * 1_000)
            );
        }
        assert_eq!(t.extend(6_000_000, 6_000 * MS + 1), continued(6_000_000));
    }

    #[test]
    fn a_resume_point_near_the_first_frame_continues_and_a_far_one_is_ignored() {
        let mut t = TimeExtender::default();
        t.resume_from((5 << 32) + 100, None);
        assert_eq!(t.extend(10, 0), continued((5 << 32) + 10));
        assert_eq!(t.last(), Some((5 << 32) + 10));
        let mut t = TimeExtender::default();
        t.resume_from((5 << 32) + 100, None);
        assert_eq!(
            t.extend(100 + 10 * 60 * 1_000_000 + 1, 0).continuity,
            Continuity::ResumeIgnored
        );
        let mut t = TimeExtender::default();
        t.resume_from(100, None);
        // Behind the point by more than the tolerance.
        let e = t.extend(u32::MAX - 600_000, 0);
        assert_eq!(
            e,
            ExtendedTime {
                time_us: u64::from(u32::MAX - 600_000),
                continuity: Continuity::ResumeIgnored
            }
        );
    }
}
