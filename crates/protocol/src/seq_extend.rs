//! One frame type's 16-bit wire sequence number extended to 64 bits, and what each frame is: new
//! (with the frames lost before it), a duplicate, a late (reordered) frame, or a sequence jump.
//!
//! Every frame is placed against the newest extended number seen, by the 16-bit difference read as
//! signed (−32 768..32 767):
//! - a forward step k (1..=32 767) is new: k − 1 frames lost — unless it is implausibly large for
//!   the receive-clock time that passed (see [`crate::arrival`]), which is a **sequence
//!   jump** (the device restarted or corrupted its counter): no loss, and the extension re-bases so
//!   that the frame gets the next number. Until the type's period is learnt
//!   ([`crate::frame_period`]), every forward step counts as losses.
//! - a number received before is a **duplicate**: not delivered.
//! - a number behind the newest, within the window of [`WINDOW`] numbers, not received yet is
//!   **late**: not delivered (consumers need increasing numbers: a strapdown integrator cannot
//!   integrate backwards), and taken back out of the lost count when its gap counted it.
//! - a number [`WINDOW`] or more behind the newest cannot be told a duplicate from a late frame. It
//!   is either a stray frame far out of place (a corrupted number, a device resending an old
//!   frame) or the first of a counter that restarted there; the next frame tells which. Until
//!   then it is **late** (not delivered, never counted lost). When the next frame continues its
//!   number, the counter restarted: a **sequence jump**, re-based there and delivered. When the
//!   next frame continues the newest, it was a stray frame and nothing changes: re-basing on it
//!   would read the following frames as a forward step of as many numbers, all "lost". After a
//!   reconnect ([`SeqExtender::reconnected`]) the device was away and has likely restarted: the
//!   first frame that far behind is a jump at once.
//!
//! - a number behind the newest after the type was silent for longer than the window lasts (an
//!   outage of more than 2^15 frames reads backwards) is a sequence jump too.
//!
//! A counter that restarts to a number less than [`WINDOW`] behind the newest, without an outage,
//! is indistinguishable from reordering: its frames count as duplicates or late until its numbers
//! pass the newest.

use super::arrival::ArrivalAnchor;
use super::continuity::Continuity;
use super::frame_period::FramePeriod;
use super::lost_runs::LostRuns;
use super::seq_window::{ReceivedWindow, WINDOW};

/// What one frame is, by its sequence number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SeqVerdict {
    /// Deliver it under the extended number `seq`; its step skipped `lost` frames.
    New {
        /// The frame's extended sequence number.
        seq: u64,
        /// Frames counted lost before this one (0 after a sequence jump).
        lost: u64,
        /// Whether the numbering continued, was re-based (a jump), or ignored the resume point.
        continuity: Continuity,
    },
    /// Received before: drop it.
    Duplicate,
    /// Behind the newest, not received before: drop it. `recovered` when it had been counted lost.
    Late {
        /// The frame had been counted lost and no longer is.
        recovered: bool,
    },
}

/// A forward step is a jump when it puts the counter this far ahead of the receive clock: far
/// above the read scheduling and burst jitter (milliseconds), below any counter jump worth seeing.
const SLACK_NS: u64 = 500_000_000;
/// Plus this many periods, for slow types (a baro frame every 20 ms).
const SLACK_PERIODS: u64 = 16;
/// Plus this fraction of the anchor's age, for the learnt period's error.
const SLACK_AGE_DIVISOR: u64 = 16;

/// Steps below this, from a resume point to the first frame, continue the point.
const RESUME_MAX_STEP: u16 = 1 << 15;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Newest {
    seq: u64,
    wire: u16,
    rx_ns: u64,
}

/// One frame type's sequence number extension and classification (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct SeqExtender {
    newest: Option<Newest>,
    window: ReceivedWindow,
    /// Numbers from here up to the newest that are not received were counted lost; those below
    /// came before the first frame or a re-base, and were never counted.
    counted_from: u64,
    /// Extended number of the last frame a previous run published and its wire number (when
    /// known), until the first frame.
    resume: Option<(u64, Option<u16>)>,
    period: FramePeriod,
    /// In frames of the learnt period (set once the period is known).
    anchor: ArrivalAnchor,
    /// The wire number of the last frame [`WINDOW`] or more behind the newest, until the next
    /// frame shows whether a counter restarted there.
    far_behind: Option<u16>,
    /// The last runs of numbers counted lost, to recover one arriving beyond the window.
    lost_runs: LostRuns,
    /// The line was reopened and no frame of this type arrived since.
    reconnected: bool,
}

impl SeqExtender {
    /// Classifies the frame numbered `wire` on the wire, received at `rx_ns` (CLOCK_MONOTONIC).
    pub fn extend(&mut self, wire: u16, rx_ns: u64) -> SeqVerdict {
        let reconnected = std::mem::take(&mut self.reconnected);
        let Some(newest) = self.newest else {
            return self.first(wire, rx_ns);
        };
        // Truncation intended: the signed 16-bit difference.
        let step = wire.wrapping_sub(newest.wire) as i16;
        if step > 0 {
            // The counter goes on: a frame far behind it was a stray one.
            self.far_behind = None;
            let k = step.unsigned_abs().into();
            let seq = newest.seq.saturating_add(k);
            if self.runs_ahead(seq, rx_ns) {
                return self.rebase(wire, rx_ns);
            }
            self.window.advance(k);
            self.lost_runs.add(newest.seq.saturating_add(1), seq);
            self.accept(seq, wire, rx_ns);
            return SeqVerdict::New {
                seq,
                lost: k - 1,
                continuity: Continuity::Continued,
            };
        }
        let behind = u64::from(step.unsigned_abs());
        if self.silent_beyond_the_window(newest.rx_ns, rx_ns) {
            return self.rebase(wire, rx_ns);
        }
        // Checked before the window: a counter restarted right at its edge continues into it.
        if self
            .far_behind
            .is_some_and(|prev| wire == prev.wrapping_add(1))
        {
            return self.rebase(wire, rx_ns);
        }
        // The frame's own number, when it is one whose loss was counted.
        let counted = newest
            .seq
            .checked_sub(behind)
            .filter(|&n| n >= self.counted_from);
        if behind >= WINDOW {
            if reconnected {
                return self.rebase(wire, rx_ns);
            }
            self.far_behind = Some(wire);
            let recovered = counted.is_some_and(|n| self.lost_runs.recover(n));
            return SeqVerdict::Late { recovered };
        }
        if self.window.received(behind) {
            return SeqVerdict::Duplicate;
        }
        self.window.mark(behind);
        // Taken out of the runs too, so that a later copy beyond the window is not recovered
        // again.
        let recovered = counted.inspect(|&n| {
            self.lost_runs.recover(n);
        });
        SeqVerdict::Late {
            recovered: recovered.is_some(),
        }
    }

    /// Continues after `last`, the extended number of a frame published earlier by a previous run
    /// of this process, so that the numbers never run backwards downstream. The first frame then
    /// continues it when its wire number lies 0..2^15 steps ahead of `last`'s (the step is not
    /// counted lost: `last` may be up to a second old, and the frames in between were published by
    /// that run); otherwise the point is ignored ([`Continuity::ResumeIgnored`]).
    /// `last_wire`: the wire number `last` was given to (after a jump its low bits are not it).
    pub fn resume_from(&mut self, last: u64, last_wire: Option<u16>) {
        *self = Self {
            resume: Some((last, last_wire)),
            ..Self::default()
        };
    }

    /// The line was reopened (the device was away): its next frame, if far behind the newest, is
    /// taken for a restarted counter at once rather than after the frame that continues it.
    pub fn reconnected(&mut self) {
        self.reconnected = true;
    }

    /// The extended number of the newest frame (before the first, the resume point's).
    pub fn last(&self) -> Option<u64> {
        self.newest.map(|n| n.seq).or(self.resume.map(|r| r.0))
    }

    /// The wire number of the newest frame (before the first, the resume point's).
    pub fn last_wire(&self) -> Option<u16> {
        self.newest
            .map(|n| n.wire)
            .or(self.resume.and_then(|r| r.1))
    }

    /// The learnt frame period, ns.
    pub fn period_ns(&self) -> Option<u64> {
        self.period.period_ns()
    }

    fn first(&mut self, wire: u16, rx_ns: u64) -> SeqVerdict {
        let (seq, continuity) = match self.resume.take() {
            // Truncation intended: the point's wire number when not saved.
            Some((last, last_wire)) => match wire.wrapping_sub(last_wire.unwrap_or(last as u16)) {
                step if step < RESUME_MAX_STEP => {
                    (last.saturating_add(step.into()), Continuity::Continued)
                }
                _ => (u64::from(wire), Continuity::ResumeIgnored),
            },
            None => (u64::from(wire), Continuity::Continued),
        };
        self.window = ReceivedWindow::newest_only();
        self.counted_from = seq;
        self.accept(seq, wire, rx_ns);
        SeqVerdict::New {
            seq,
            lost: 0,
            continuity,
        }
    }

    /// A sequence jump: the frame gets the next number, and what came before no longer tells
    /// anything about the numbers that follow.
    fn rebase(&mut self, wire: u16, rx_ns: u64) -> SeqVerdict {
        let seq = self
            .newest
            .map_or(u64::from(wire), |n| n.seq.saturating_add(1));
        self.window = ReceivedWindow::newest_only();
        self.counted_from = seq;
        self.far_behind = None;
        self.lost_runs = LostRuns::default();
        self.period.discard_block();
        self.newest = Some(Newest { seq, wire, rx_ns });
        if let Some(p) = self.period.period_ns() {
            self.anchor.observe(seq, p, rx_ns);
        }
        SeqVerdict::New {
            seq,
            lost: 0,
            continuity: Continuity::Rebased,
        }
    }

    fn accept(&mut self, seq: u64, wire: u16, rx_ns: u64) {
        self.newest = Some(Newest { seq, wire, rx_ns });
        self.period.observe(seq, rx_ns);
        if let Some(p) = self.period.period_ns() {
            self.anchor.observe(seq, p, rx_ns);
        }
    }

    /// Whether the type was silent for longer than the window lasts, so that a number behind the
    /// newest cannot be a late frame (after an outage of more than 2^15 frames, the step reads
    /// backwards). Never before the period is learnt.
    fn silent_beyond_the_window(&self, newest_rx_ns: u64, rx_ns: u64) -> bool {
        self.period.period_ns().is_some_and(|p| {
            rx_ns.saturating_sub(newest_rx_ns) > WINDOW.saturating_mul(p).saturating_add(SLACK_NS)
        })
    }

    /// Whether numbering the frame `seq` puts the counter implausibly far ahead of the receive
    /// clock. Never before the period is learnt.
    fn runs_ahead(&self, seq: u64, rx_ns: u64) -> bool {
        let Some(p) = self.period.period_ns() else {
            return false;
        };
        let slack = SLACK_NS
            .saturating_add(SLACK_PERIODS.saturating_mul(p))
            .saturating_add(self.anchor.age_ns(rx_ns) / SLACK_AGE_DIVISOR);
        self.anchor
            .ahead_ns(seq, p, rx_ns)
            .is_some_and(|ahead| ahead > i128::from(slack))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    fn new(seq: u64, lost: u64) -> SeqVerdict {
        SeqVerdict::New {
            seq,
            lost,
            continuity: Continuity::Continued,
        }
    }

    /// Frames `from..to` (wire numbers, wrapping) at 1 kHz from receive time `rx0`.
    fn feed(s: &mut SeqExtender, from: u64, to: u64, rx0: u64) {
        for k in from..to {
            let v = s.extend(k as u16, rx0 + (k - from) * MS);
            assert!(matches!(v, SeqVerdict::New { lost: 0, .. }), "{k}: {v:?}");
        }
    }

    #[test]
    fn gaps_across_the_wrap_and_the_largest_forward_step() {
        let mut s = SeqExtender::default();
        assert_eq!(s.extend(65534, 0), new(65534, 0));
        assert_eq!(s.extend(65535, 0), new(65535, 0));
        assert_eq!(s.extend(0, 0), new(65536, 0));
        assert_eq!(s.extend(3, 0), new(65539, 2));
        // 32 767 forward, no period known: 32 766 lost.
        assert_eq!(s.extend(3 + 32767, 0), new(65539 + 32767, 32766));
        assert_eq!(s.extend(3 + 32767, 0), SeqVerdict::Duplicate);
    }

    #[test]
    fn one_reordered_frame_is_late_and_not_lost() {
        let mut s = SeqExtender::default();
        assert_eq!(s.extend(10, 0), new(10, 0));
        assert_eq!(s.extend(12, 0), new(12, 1));
        assert_eq!(s.extend(11, 0), SeqVerdict::Late { recovered: true });
        assert_eq!(s.extend(11, 0), SeqVerdict::Duplicate);
        assert_eq!(s.extend(13, 0), new(13, 0));
        // Before the first frame: late, but it was never counted lost.
        assert_eq!(s.extend(9, 0), SeqVerdict::Late { recovered: false });
    }

    #[test]
    fn a_jump_of_30000_then_back_1_and_100() {
        let mut s = SeqExtender::default();
        feed(&mut s, 0, 5_000, 0);
        assert_eq!(s.period_ns(), Some(MS));
        let rx = 5_000 * MS;
        let jumped = s.extend(4_999 + 30_000, rx);
        assert_eq!(
            jumped,
            SeqVerdict::New {
                seq: 5_000,
                lost: 0,
                continuity: Continuity::Rebased
            }
        );
        // Behind the re-based newest: late, never counted lost.
        assert_eq!(
            s.extend(4_999 + 30_000 - 1, rx + MS),
            SeqVerdict::Late { recovered: false }
        );
        assert_eq!(
            s.extend(4_999 + 30_000 - 100, rx + 2 * MS),
            SeqVerdict::Late { recovered: false }
        );
        // The jumped counter goes on: numbers continue from the re-based one.
        assert_eq!(s.extend(5_000 + 30_000, rx + 3 * MS), new(5_001, 0));
    }

    #[test]
    fn a_plausible_gap_after_an_outage_is_lost_frames() {
        let mut s = SeqExtender::default();
        feed(&mut s, 0, 5_000, 0);
        // Unplugged 5 s: 5 000 frames went by on the receive clock too.
        assert_eq!(s.extend(9_999, 9_999 * MS), new(9_999, 4_999));
        // 600 frames ahead of the receive clock (0.6 s, slack 0.516 s): a jump.
        assert!(matches!(
            s.extend(10_000 + 600, 10_000 * MS),
            SeqVerdict::New {
                continuity: Continuity::Rebased,
                ..
            }
        ));
    }

    #[test]
    fn a_backlog_with_its_middle_dropped_loses_frames_without_a_jump() {
        let mut s = SeqExtender::default();
        feed(&mut s, 0, 5_000, 0);
        // Reader stalled 3 s: the kernel held frames 5 000..6 000, read late; the device's
        // frames 6 000..8 000 were dropped; 8 000 on arrives on time.
        let rx = 8_000 * MS;
        for k in 5_000..6_000 {
            assert_eq!(s.extend(k as u16, rx), new(k, 0));
        }
        assert_eq!(s.extend(8_000, rx + MS / 2), new(8_000, 2_000));
        assert_eq!(s.extend(8_001, rx + MS), new(8_001, 0));
    }

    #[test]
    fn behind_after_a_silence_longer_than_the_window_is_a_jump() {
        let mut s = SeqExtender::default();
        feed(&mut s, 0, 5_000, 0);
        // Unplugged 65 s: 65 000 frames on, the step reads 536 back.
        let wire = (4_999 + 65_000) as u16;
        assert_eq!(
            s.extend(wire, (4_999 + 65_000) * MS),
            SeqVerdict::New {
                seq: 5_000,
                lost: 0,
                continuity: Continuity::Rebased
            }
        );
        assert_eq!(s.extend(wire.wrapping_add(1), 70_000 * MS), new(5_001, 0));
    }

    #[test]
    fn far_behind_and_continued_is_a_jump_backwards() {
        let mut s = SeqExtender::default();
        s.extend(5_000, 0);
        // Too old to tell: late, until the next frame says more.
        assert_eq!(
            s.extend(5_000 - WINDOW as u16, 0),
            SeqVerdict::Late { recovered: false }
        );
        // Continued: the counter restarted there.
        assert_eq!(
            s.extend(5_001 - WINDOW as u16, 0),
            SeqVerdict::New {
                seq: 5_001,
                lost: 0,
                continuity: Continuity::Rebased
            }
        );
        assert_eq!(s.extend(5_002 - WINDOW as u16, 0), new(5_002, 0));
    }

    #[test]
    fn far_behind_once_is_a_stray_frame_and_changes_nothing() {
        let mut s = SeqExtender::default();
        s.extend(5_000, 0);
        assert_eq!(s.extend(3_208, 0), SeqVerdict::Late { recovered: false });
        // The counter goes on from the newest: nothing lost, no jump.
        assert_eq!(s.extend(5_001, 0), new(5_001, 0));
        // A stray frame is not a restart just because another stray one precedes it by one,
        // once the counter went on in between.
        assert_eq!(s.extend(3_209, 0), SeqVerdict::Late { recovered: false });
        assert_eq!(s.extend(5_002, 0), new(5_002, 0));
        assert_eq!(s.extend(3_210, 0), SeqVerdict::Late { recovered: false });
    }

    #[test]
    fn a_resume_continues_forward_without_counting_the_step_or_is_ignored() {
        // A previous run published up to 200_005 (wire 200_005 mod 2^16 = 3_397).
        let mut r = SeqExtender::default();
        r.resume_from(200_005, None);
        assert_eq!(r.extend(3_400, 0), new(200_008, 0));
        assert_eq!(r.extend(3_402, 0), new(200_010, 1));
        // A first frame behind the point (step ≥ 2^15): the point is ignored.
        let mut r = SeqExtender::default();
        r.resume_from(200_005, None);
        assert_eq!(
            r.extend(3_000, 0),
            SeqVerdict::New {
                seq: 3_000,
                lost: 0,
                continuity: Continuity::ResumeIgnored
            }
        );
    }
}
