//! Choosing between the two navigator lanes: one contiguous navigation stream out of two.
//!
//! The selector delivers every sequence number once, in order, from the lane it has selected, and
//! keeps the other lane's samples that are ahead of the output so that a switch continues exactly
//! at the next sequence number: killing the selected lane loses no sample.
//!
//! Switching rule, built against the known failure modes of lane switching:
//! - **Dead lane** (liveness): the selected lane has delivered nothing beyond the output while the
//!   other lane is [`SelectorConfig::switch_lag`] samples ahead *and* the selected lane has been
//!   silent for [`SelectorConfig::dead_after_ns`]. Silence is measured on the navigators' publish
//!   times, from the later of the selected lane's last sample and the other lane's first sample
//!   the selected lane still owes: a lane is late only once there was work for it to do. So one
//!   late sample is not a failure (no switch on a glitch), nor is a burst: when the input resumes
//!   after a gap (a starved acquisition, a restarted fusion replaying its history, the serial
//!   line delivering what waited in it), both lanes work through hundreds of samples within a
//!   few milliseconds and one is briefly ahead; the time since the selected lane's last sample
//!   then includes the gap, in which no lane had anything to do, and must not count.
//!   Samples without publish times are judged by the count alone.
//! - **Full ring**: the other lane's pending samples fill the ring. The consumer then stops
//!   taking that lane's samples ([`LaneSelector::has_room`]; they wait in its queue) and the
//!   selected lane is still only left once it has been silent for the dead time, on the
//!   consumer's clock (the other lane's newest publish time no longer moves while nothing is
//!   taken). A selected lane merely late by less than the dead time is never left.
//! - **Untrusted lane** (quality): the selected lane is aligning, its solution invalid, or younger than
//!   [`SelectorConfig::settle`] samples (it just reset or took over), while the other lane is trusted
//!   and has the next sample. A lane that just reset is never chosen for quality: only a dead
//!   selected lane makes the selector take an untrusted one, since anything beats no output.
//! - **Holes** in the selected lane (a sample it skipped while the other lane has it) are filled
//!   from the other lane without switching.
//! - **No flip-flop**: nothing else switches. A healthy selected lane stays selected however the
//!   other lane does (there is no preferred lane to return to), and a quality switch needs
//!   [`SelectorConfig::min_dwell`] samples since the last switch.
//!
//! Every switch says why ([`SwitchReason`]) and is counted by cause ([`SwitchCounts`]).
//! Allocation-free after construction: each lane's pending samples sit in a fixed ring.

use std::collections::VecDeque;

use ipc_types::{NavState, Stage};

use crate::lanes::switch::{Switch, SwitchCounts, SwitchReason};
use crate::lanes::trust::distrust;

/// Number of navigator lanes.
pub const LANES: usize = 2;

/// Pending samples kept per lane; more than any switch lag and than a burst that builds up while
/// the selected lane is silent for less than the dead time, so a switch always finds the next one.
pub const PENDING: usize = 512;

/// When the selector leaves a lane for the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelectorConfig {
    /// Samples the other lane must be ahead of the output before the selected lane counts as dead.
    pub switch_lag: u64,
    /// And how long the selected lane must have been silent while the other lane published, ns
    /// (samples without publish times are judged by the count alone).
    pub dead_after_ns: u64,
    /// The same when the other lane is not trusted (aligning, invalid, or younger than `settle`).
    pub dead_after_untrusted_ns: u64,
    /// Samples a solution must have run (since alignment or takeover) before it is trusted.
    pub settle: u64,
    /// Samples between a switch and a quality switch.
    pub min_dwell: u64,
}

impl Default for SelectorConfig {
    /// At the block's 1 kHz: a dead lane is left after 8 ms (100 ms for a lane not trusted yet), a
    /// solution trusted after 2 s, at most one quality switch per second.
    fn default() -> Self {
        Self {
            switch_lag: 8,
            dead_after_ns: 8_000_000,
            dead_after_untrusted_ns: 100_000_000,
            settle: 2000,
            min_dwell: 1000,
        }
    }
}

/// See the module documentation.
#[derive(Debug, Clone)]
pub struct LaneSelector {
    config: SelectorConfig,
    pending: [VecDeque<NavState>; LANES],
    selected: usize,
    last_delivered: Option<u64>,
    /// Navigator publish time of the newest sample delivered from the selected lane (0: none yet,
    /// or unstamped).
    selected_published_ns: u64,
    last_switch_seq: Option<u64>,
    counts: SwitchCounts,
    last_switch: Option<Switch>,
    filled: u64,
    overwritten: u64,
}

/// A navigator's publish time of `s`, `None` for a sample without one.
fn published_ns(s: &NavState) -> Option<u64> {
    Some(s.header.stage_ns(Stage::Navigator)).filter(|&ns| ns != 0)
}

impl LaneSelector {
    /// A selector with nothing received yet, delivering lane 0 first.
    pub fn new(config: SelectorConfig) -> Self {
        Self {
            config,
            pending: std::array::from_fn(|_| VecDeque::with_capacity(PENDING)),
            selected: 0,
            last_delivered: None,
            selected_published_ns: 0,
            last_switch_seq: None,
            counts: SwitchCounts::default(),
            last_switch: None,
            filled: 0,
            overwritten: 0,
        }
    }

    /// The lane delivering now.
    pub fn selected(&self) -> usize {
        self.selected
    }

    /// Lane changes since start.
    pub fn switches(&self) -> u64 {
        self.counts.total()
    }

    /// Lane changes since start, by cause.
    pub fn switch_counts(&self) -> SwitchCounts {
        self.counts
    }

    /// The most recent lane change.
    pub fn last_switch(&self) -> Option<Switch> {
        self.last_switch
    }

    /// Whether `lane`'s ring takes another sample without overwriting its oldest pending one. A
    /// consumer leaves a lane's samples in its queue while not.
    pub fn has_room(&self, lane: usize) -> bool {
        self.pending.get(lane).is_some_and(|q| q.len() < PENDING)
    }

    /// Sequence number of `lane`'s oldest pending sample.
    pub fn next_seq(&self, lane: usize) -> Option<u64> {
        self.pending.get(lane)?.front().map(|s| s.header.origin_seq)
    }

    /// Pending samples overwritten because a lane's ring was full (a consumer that pushes without
    /// asking [`LaneSelector::has_room`]).
    pub fn overwritten(&self) -> u64 {
        self.overwritten
    }

    /// Takes one sample of `lane` (samples of a lane arrive in sequence order). Samples at or before
    /// the output are useless and dropped; when the ring is full the oldest pending one goes.
    pub fn push(&mut self, lane: usize, sample: NavState) {
        let Some(queue) = self.pending.get_mut(lane) else {
            return;
        };
        if self
            .last_delivered
            .is_some_and(|d| sample.header.origin_seq <= d)
        {
            return;
        }
        // A lane that restarted begins again below what it had pending: its old samples are stale.
        while queue
            .back()
            .is_some_and(|b| b.header.origin_seq >= sample.header.origin_seq)
        {
            queue.pop_back();
        }
        if queue.len() == PENDING {
            queue.pop_front();
            self.overwritten += 1;
        }
        queue.push_back(sample);
    }

    /// The next sample of the output stream, or `None` until one is due; time is read from the
    /// navigators' publish times alone.
    pub fn pop(&mut self) -> Option<NavState> {
        self.pop_at(0)
    }

    /// [`LaneSelector::pop`] for a consumer whose clock (CLOCK_MONOTONIC, ns, as the navigators
    /// stamp) reads `now_ns`: a full ring of the other lane is timed on it.
    pub fn pop_at(&mut self, now_ns: u64) -> Option<NavState> {
        self.discard_delivered();
        let other = 1 - self.selected;
        if let Some(reason) = self.switch_reason(other, now_ns) {
            self.switch_to(other, reason);
        }
        let next = self.pending[self.selected].front()?.header.origin_seq;
        // A sample the selected lane skipped but the other lane has fills the hole; the selection
        // stays (one missing sample is a glitch, not a failure).
        let lane = if self.pending[other]
            .front()
            .is_some_and(|s| s.header.origin_seq < next)
        {
            self.filled += 1;
            other
        } else {
            self.selected
        };
        let sample = self.pending[lane].pop_front()?;
        self.last_delivered = Some(sample.header.origin_seq);
        if lane == self.selected {
            self.selected_published_ns = sample.header.stage_ns(Stage::Navigator);
        }
        Some(sample)
    }

    /// Samples taken from the other lane to fill a hole in the selected lane's output.
    pub fn filled(&self) -> u64 {
        self.filled
    }

    fn discard_delivered(&mut self) {
        let Some(d) = self.last_delivered else {
            return;
        };
        for queue in &mut self.pending {
            while queue.front().is_some_and(|s| s.header.origin_seq <= d) {
                queue.pop_front();
            }
        }
    }

    /// Why the selector should leave the selected lane for `other` now, if it should.
    fn switch_reason(&self, other: usize, now_ns: u64) -> Option<SwitchReason> {
        let candidate = self.pending[other].front()?;
        let candidate_distrust = distrust(candidate, self.config.settle);
        let selected = &self.pending[self.selected];
        let Some(next) = selected.front() else {
            return self.dead_reason(other, candidate_distrust.is_none(), now_ns);
        };
        // Untrusted: only towards a trusted lane that has the next sample (not behind the
        // selected one), and not within the dwell time of the last switch.
        let dwelt = self
            .last_switch_seq
            .is_none_or(|at| next.header.origin_seq.saturating_sub(at) >= self.config.min_dwell);
        if !dwelt
            || candidate_distrust.is_some()
            || candidate.header.origin_seq > next.header.origin_seq
        {
            return None;
        }
        distrust(next, self.config.settle).map(SwitchReason::Untrusted)
    }

    /// Nothing from the selected lane while the other has samples ahead of the output: dead once
    /// the other lane is `switch_lag` samples ahead and the selected one silent for the dead time.
    /// Counted in samples, not in sequence numbers, so that a hole in the input (both lanes skip
    /// the same numbers) is no reason to switch. Towards a lane that just reset, only after a
    /// longer silence: a selected lane that is merely starved of CPU for a few milliseconds must
    /// not hand the output to it.
    fn dead_reason(
        &self,
        other: usize,
        candidate_trusted: bool,
        now_ns: u64,
    ) -> Option<SwitchReason> {
        let pending = &self.pending[other];
        let ahead = u32::try_from(pending.len()).unwrap_or(u32::MAX);
        if u64::from(ahead) < self.config.switch_lag {
            return None;
        }
        let dead_after = if candidate_trusted {
            self.config.dead_after_ns
        } else {
            self.config.dead_after_untrusted_ns
        };
        let full = pending.len() >= PENDING;
        let (Some(first_owed), Some(newest)) = (
            pending.front().and_then(published_ns),
            pending.back().and_then(published_ns),
        ) else {
            return Some(SwitchReason::Behind { ahead });
        };
        // Silent since its last sample, or since the other lane published the first sample the
        // selected lane still owes, whichever is later: before that it had nothing to do.
        let since = self.selected_published_ns.max(first_owed);
        // With a full ring nothing newer is taken from the other lane: the consumer's clock tells
        // how the silence goes on.
        let clock = if full { newest.max(now_ns) } else { newest };
        let silent_ns = clock.saturating_sub(since);
        if silent_ns < dead_after {
            return None;
        }
        Some(if full {
            SwitchReason::RingFull { silent_ns, ahead }
        } else {
            SwitchReason::Silent { silent_ns, ahead }
        })
    }

    fn switch_to(&mut self, lane: usize, reason: SwitchReason) {
        let at_seq = self.pending[lane]
            .front()
            .map_or(0, |s| s.header.origin_seq);
        self.last_switch = Some(Switch {
            from: self.selected,
            to: lane,
            reason,
            at_seq,
        });
        self.selected = lane;
        // The new lane's clock starts with its first delivery.
        self.selected_published_ns = 0;
        self.last_switch_seq = Some(at_seq);
        self.counts.count(reason);
    }
}

#[cfg(test)]
mod tests {
    use ipc_types::NavMode;

    use super::*;
    use crate::lanes::test_samples::{SETTLE, aligning, nav};
    use crate::lanes::trust::Distrust;

    fn cfg() -> SelectorConfig {
        SelectorConfig {
            switch_lag: 8,
            dead_after_ns: 8_000_000,
            dead_after_untrusted_ns: 100_000_000,
            settle: SETTLE,
            min_dwell: 50,
        }
    }

    /// A navigating solution of `lane` at `seq` that started at `start`.
    fn drain(sel: &mut LaneSelector, out: &mut Vec<(u64, u8)>) {
        while let Some(s) = sel.pop() {
            out.push((s.header.origin_seq, s.lane));
        }
    }

    #[test]
    fn healthy_lanes_deliver_the_selected_lane_once_in_order() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        for seq in 1..=1000 {
            // The standby is sometimes first: its samples are never taken while lane 0 is healthy.
            sel.push(1, nav(1, seq, 1));
            sel.push(0, nav(0, seq, 1));
            drain(&mut sel, &mut out);
        }
        assert_eq!(out.len(), 1000);
        assert!(
            out.iter()
                .enumerate()
                .all(|(i, &(s, l))| s == i as u64 + 1 && l == 0)
        );
        assert_eq!(sel.switches(), 0);
    }

    #[test]
    fn a_killed_lane_loses_no_sample_and_the_gap_is_the_switch_lag() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut stall = 0;
        for seq in 1..=500 {
            sel.push(1, nav(1, seq, 1));
            if seq <= 200 {
                sel.push(0, nav(0, seq, 1));
            }
            let before = out.len();
            drain(&mut sel, &mut out);
            if out.len() == before {
                stall += 1;
            }
        }
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=500).collect::<Vec<_>>());
        // Lane 1 needs to be `switch_lag` ahead of the output (seq 200): 207 arrives without
        // output, 208 switches.
        assert_eq!(stall, 7);
        assert_eq!(
            sel.last_switch(),
            Some(Switch {
                from: 0,
                to: 1,
                reason: SwitchReason::Behind { ahead: 8 },
                at_seq: 201
            })
        );
        assert!(out[200..].iter().all(|o| o.1 == 1));
    }

    #[test]
    fn a_late_sample_is_not_a_failure() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        for seq in 1..=300 {
            sel.push(1, nav(1, seq, 1));
            // Lane 0 delivers samples 100..=106 late, in one burst after 106 of lane 1.
            if !(100..=106).contains(&seq) {
                if seq == 107 {
                    for late in 100..=106 {
                        sel.push(0, nav(0, late, 1));
                    }
                }
                sel.push(0, nav(0, seq, 1));
            }
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        assert!(out.iter().all(|o| o.1 == 0));
        assert_eq!(out.len(), 300);
    }

    /// [`nav`] published by its navigator at `ns`.
    fn stamped(lane: u8, seq: u64, ns: u64) -> NavState {
        let mut s = nav(lane, seq, 1);
        s.header.stamp(Stage::Navigator, ns);
        s
    }

    const MS: u64 = 1_000_000;

    #[test]
    fn a_burst_with_the_other_lane_ahead_is_not_a_dead_lane() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        for seq in 1..=100 {
            sel.push(0, stamped(0, seq, seq * MS));
            sel.push(1, stamped(1, seq, seq * MS));
            drain(&mut sel, &mut out);
        }
        // A replayed history: 300 samples within 0.3 ms, lane 1 working through 40 at a time
        // before lane 0 catches up.
        let t0 = 101 * MS;
        for chunk in (101..=400u64).collect::<Vec<_>>().chunks(40) {
            for &seq in chunk {
                sel.push(1, stamped(1, seq, t0 + seq * 1_000));
            }
            drain(&mut sel, &mut out);
            for &seq in chunk {
                sel.push(0, stamped(0, seq, t0 + seq * 1_000 + 500));
            }
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        assert_eq!(out.len(), 400);
        assert!(
            out.iter()
                .enumerate()
                .all(|(i, &(s, l))| s == i as u64 + 1 && l == 0)
        );
    }

    #[test]
    fn a_silent_lane_is_left_after_the_dead_time() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut stall = 0;
        for seq in 1..=300 {
            sel.push(1, stamped(1, seq, seq * MS));
            if seq <= 200 {
                sel.push(0, stamped(0, seq, seq * MS));
            }
            let before = out.len();
            drain(&mut sel, &mut out);
            stall += u32::from(out.len() == before);
        }
        // Lane 1 publishes 209 at 209 ms, 8 ms after its 201, the first sample lane 0 owed: the
        // switch.
        assert_eq!(stall, 8);
        assert_eq!(
            sel.last_switch().map(|s| (s.to, s.at_seq, s.reason)),
            Some((
                1,
                201,
                SwitchReason::Silent {
                    silent_ns: 8 * MS,
                    ahead: 9
                }
            ))
        );
        assert_eq!(out.len(), 300);
    }

    #[test]
    fn a_starved_lane_is_not_left_for_one_that_just_reset() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        // Lane 1 restarted at 701: not trusted until its solution has run SETTLE (100) samples.
        let young = |seq: u64, ns: u64| {
            let mut s = stamped(1, seq, ns);
            s.solution_start_seq = 701;
            s
        };
        for seq in 1..=700 {
            sel.push(0, stamped(0, seq, seq * MS));
            drain(&mut sel, &mut out);
        }
        // Lane 0 starved of CPU for 50 ms while lane 1 publishes 701..=750, then catches up.
        for seq in 701..=750 {
            sel.push(1, young(seq, seq * MS));
            drain(&mut sel, &mut out);
        }
        for seq in 701..=760 {
            sel.push(0, stamped(0, seq, 751 * MS + seq));
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        assert!(out.iter().all(|o| o.1 == 0));
        assert_eq!(out.len(), 760);
        // Lane 0 silent for good: after 100 ms lane 1 takes over, young as it is (anything beats
        // no output), from the next sample on.
        for seq in 761..=880 {
            sel.push(1, young(seq, seq * MS));
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.last_switch().map(|s| (s.to, s.at_seq)), Some((1, 761)));
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=880).collect::<Vec<_>>());
    }

    /// A consumer's pass: takes each lane's samples published by `now` while its ring has room,
    /// then delivers what is due on its clock.
    fn consume(
        sel: &mut LaneSelector,
        lanes: &mut [std::collections::VecDeque<NavState>; 2],
        now: u64,
        out: &mut Vec<(u64, u8)>,
    ) {
        loop {
            let mut pulled = false;
            for (lane, queue) in lanes.iter_mut().enumerate() {
                if sel.has_room(lane)
                    && queue
                        .front()
                        .is_some_and(|s| s.header.stage_ns(Stage::Navigator) <= now)
                    && let Some(s) = queue.pop_front()
                {
                    sel.push(lane, s);
                    pulled = true;
                }
            }
            while let Some(s) = sel.pop_at(now) {
                out.push((s.header.origin_seq, s.lane));
            }
            if !pulled {
                return;
            }
        }
    }

    #[test]
    fn a_burst_that_fills_the_ring_waits_for_the_dead_time_and_loses_nothing() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut lanes: [std::collections::VecDeque<NavState>; 2] = Default::default();
        for seq in 1..=100 {
            for (lane, queue) in lanes.iter_mut().enumerate() {
                queue.push_back(stamped(lane as u8, seq, seq * MS));
            }
        }
        // The input stops for 300 ms, then 1000 samples arrive at once: lane 1 works through
        // them within 1 ms at 400 ms, lane 0 (waiting for a CPU) 5 ms later.
        let burst = 101..=1100u64;
        for seq in burst.clone() {
            lanes[1].push_back(stamped(1, seq, 400 * MS + seq * 1_000));
        }
        for seq in burst {
            lanes[0].push_back(stamped(0, seq, 405 * MS + seq * 1_000));
        }
        for now in (1..=420).map(|ms| ms * MS) {
            consume(&mut sel, &mut lanes, now, &mut out);
        }
        assert_eq!((sel.switches(), sel.overwritten()), (0, 0));
        assert!(out.iter().all(|o| o.1 == 0));
        // Lane 0 is gone; lane 1 delivers another burst of 1000 at 500 ms. Its ring fills within
        // a millisecond and the rest waits in its queue: the switch comes when lane 0 has been
        // silent for the dead time on the consumer's clock, from the first sample it owed.
        for seq in 1101..=2100u64 {
            lanes[1].push_back(stamped(1, seq, 500 * MS + (seq - 1100) * 500));
        }
        let mut switched_at = None;
        for now in (421..=600).map(|ms| ms * MS) {
            consume(&mut sel, &mut lanes, now, &mut out);
            if switched_at.is_none() && sel.switches() == 1 {
                switched_at = Some(now);
            }
        }
        let first_owed = 500 * MS + 500;
        assert_eq!(switched_at, Some(first_owed - 500 + 9 * MS));
        let switch = sel.last_switch().expect("switched");
        assert_eq!((switch.to, switch.at_seq), (1, 1101));
        let SwitchReason::RingFull { silent_ns, ahead } = switch.reason else {
            panic!("{switch:?}");
        };
        assert_eq!(ahead as usize, PENDING);
        assert!((8 * MS..9 * MS).contains(&silent_ns), "{silent_ns}");
        assert_eq!(sel.switch_counts().ring_full, 1);
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=2100).collect::<Vec<_>>());
        assert_eq!(sel.overwritten(), 0);
    }

    #[test]
    fn a_ring_overwritten_by_a_consumer_that_does_not_ask_is_counted() {
        let mut sel = LaneSelector::new(cfg());
        for seq in 1..=PENDING as u64 + 3 {
            assert_eq!(sel.has_room(1), seq <= PENDING as u64);
            sel.push(1, stamped(1, seq, MS + seq));
        }
        assert_eq!(sel.overwritten(), 3);
        assert!(!sel.has_room(7));
    }

    #[test]
    fn a_selected_lane_late_by_less_than_the_dead_time_is_kept() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut lanes: [std::collections::VecDeque<NavState>; 2] = Default::default();
        // Lane 1 publishes every millisecond. Lane 0 keeps pace but every 100 ms is descheduled
        // and publishes the first sample it owes 7.9 ms late (just under the dead time), with the
        // others it owes at once.
        for seq in 1..=3000u64 {
            lanes[1].push_back(stamped(1, seq, seq * MS));
            let phase = seq % 100;
            let ns = if (1..=9).contains(&phase) {
                (seq - phase) * MS + 8_900_000 + phase
            } else {
                seq * MS + 100_000
            };
            lanes[0].push_back(stamped(0, seq, ns));
        }
        for now in (1..=31_000u64).map(|step| step * MS / 10) {
            consume(&mut sel, &mut lanes, now, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        assert_eq!(out.len(), 3000);
        assert!(out.iter().all(|o| o.1 == 0));
    }

    #[test]
    fn a_selected_lane_late_by_more_than_the_dead_time_is_left_and_the_silence_reported() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut lanes: [std::collections::VecDeque<NavState>; 2] = Default::default();
        // As above, but lane 0's pause at 1000 ms lasts 12 ms.
        for seq in 1..=1100u64 {
            lanes[1].push_back(stamped(1, seq, seq * MS));
            let ns = if (1001..=1012).contains(&seq) {
                1012 * MS + 100_000 + seq
            } else {
                seq * MS + 100_000
            };
            lanes[0].push_back(stamped(0, seq, ns));
        }
        for now in (1..=11_100u64).map(|step| step * MS / 10) {
            consume(&mut sel, &mut lanes, now, &mut out);
        }
        let switch = sel.last_switch().expect("switched");
        // Lane 0's last sample came at 1000.1 ms, the first it owed (1001) at 1001 ms: silent
        // from then; lane 1's 1009 at 1009 ms makes 8 ms and 9 samples ahead.
        assert_eq!(
            switch,
            Switch {
                from: 0,
                to: 1,
                reason: SwitchReason::Silent {
                    silent_ns: 8 * MS,
                    ahead: 9
                },
                at_seq: 1001
            }
        );
        assert_eq!(
            switch.to_string(),
            "lane 0 → 1 at seq 1001: lane 0 silent 8.0 ms while lane 1 was 9 samples ahead"
        );
        assert_eq!(sel.switch_counts().silent, 1);
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=1100).collect::<Vec<_>>());
    }

    #[test]
    fn a_burst_after_a_gap_in_the_input_is_not_a_dead_lane() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut lanes: [std::collections::VecDeque<NavState>; 2] = Default::default();
        for seq in 1..=100 {
            for (lane, queue) in lanes.iter_mut().enumerate() {
                queue.push_back(stamped(lane as u8, seq, seq * MS));
            }
        }
        // The input stops for 300 ms (a starved acquisition) and 300 samples arrive at once at
        // 400 ms: lane 1 takes them at 20 µs each, lane 0 gets a CPU 6 ms later; then both carry
        // on in real time. Lane 0's last sample is 306 ms old when lane 1 is 100 ahead, but it was
        // never more than 6 ms late with work to do.
        for seq in 101..=400u64 {
            lanes[1].push_back(stamped(1, seq, 400 * MS + (seq - 100) * 20_000));
            lanes[0].push_back(stamped(0, seq, 406 * MS + (seq - 100) * 20_000));
        }
        for seq in 401..=600u64 {
            lanes[1].push_back(stamped(1, seq, seq * 2 * MS));
            lanes[0].push_back(stamped(0, seq, seq * 2 * MS + 300_000));
        }
        for now in (1..=12_100u64).map(|step| step * MS / 10) {
            consume(&mut sel, &mut lanes, now, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        assert_eq!(out.len(), 600);
        assert!(out.iter().all(|o| o.1 == 0));
    }

    #[test]
    fn a_restarted_lane_is_not_chosen_until_it_settled_and_then_only_when_needed() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        // Lane 0 dies at 200; lane 1 carries on. Lane 0 restarts at 300 by taking over (its
        // solution starts at 300), is trusted from 400, but lane 1 stays selected: no flip-flop.
        for seq in 1..=1000 {
            sel.push(1, nav(1, seq, 1));
            if seq <= 200 {
                sel.push(0, nav(0, seq, 1));
            } else if seq >= 300 {
                sel.push(0, nav(0, seq, 300));
            }
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 1);
        assert_eq!(out.len(), 1000);
        assert!(out[200..].iter().all(|o| o.1 == 1));
    }

    #[test]
    fn a_selected_lane_that_resets_is_left_for_a_trusted_one_after_the_dwell() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        // Lane 0 restarts its alignment at 500 (aligning from then on); lane 1 is trusted.
        for seq in 1..=700 {
            sel.push(
                0,
                if seq < 500 {
                    nav(0, seq, 1)
                } else {
                    aligning(0, seq)
                },
            );
            sel.push(1, nav(1, seq, 1));
            drain(&mut sel, &mut out);
        }
        assert_eq!(
            sel.last_switch().map(|s| (s.to, s.reason, s.at_seq)),
            Some((1, SwitchReason::Untrusted(Distrust::Aligning), 500))
        );
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=700).collect::<Vec<_>>());
    }

    #[test]
    fn an_untrusted_lane_is_taken_only_when_the_selected_one_is_dead() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        // Both aligning at first: no quality switch between two untrusted lanes.
        for seq in 1..=50 {
            sel.push(1, aligning(1, seq));
            sel.push(0, aligning(0, seq));
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        // Lane 0 dies while lane 1 still aligns: lane 1 is taken (no output would be worse).
        for seq in 51..=80 {
            sel.push(1, aligning(1, seq));
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.selected(), 1);
        assert_eq!(out.len(), 80);
    }

    #[test]
    fn a_sample_the_selected_lane_skipped_is_filled_from_the_other() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        for seq in 1..=30 {
            if seq != 11 {
                sel.push(0, nav(0, seq, 1));
            }
            sel.push(1, nav(1, seq, 1));
            drain(&mut sel, &mut out);
        }
        assert_eq!(out.len(), 30);
        assert_eq!(out[10], (11, 1));
        assert!(out.iter().filter(|o| o.0 != 11).all(|o| o.1 == 0));
        assert_eq!((sel.filled(), sel.switches()), (1, 0));
    }

    #[test]
    fn gaps_in_both_lanes_pass_through_without_a_switch() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        // The device was unplugged: both lanes miss 101..=150 (the input never existed), and the
        // standby is first to publish after the hole.
        for seq in (1..=100).chain(151..=300) {
            sel.push(1, nav(1, seq, 1));
            drain(&mut sel, &mut out);
            sel.push(0, nav(0, seq, 1));
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 0);
        assert_eq!(out.len(), 250);
    }

    #[test]
    fn quality_switches_respect_the_dwell_time() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        // Lane 0 dies at 200 (dead switch at 201), comes back trusted; lane 1 resets at 220,
        // within the 50-sample dwell: the quality switch back waits until 251.
        for seq in 1..=400 {
            if seq <= 200 || seq >= 209 {
                sel.push(0, nav(0, seq, 1));
            }
            sel.push(
                1,
                if seq < 220 {
                    nav(1, seq, 1)
                } else {
                    aligning(1, seq)
                },
            );
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.switches(), 2);
        assert_eq!(
            sel.last_switch().map(|s| (s.to, s.reason, s.at_seq)),
            Some((0, SwitchReason::Untrusted(Distrust::Aligning), 251))
        );
        assert_eq!(out.len(), 400);
    }

    /// Lane 0 delivers `bad` at `at` (and is settled otherwise); lane 1 is trusted throughout.
    fn quality_switch(bad: impl Fn(u64) -> NavState, at: u64) -> Option<Switch> {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        for seq in 1..=at + 20 {
            sel.push(0, if seq >= at { bad(seq) } else { nav(0, seq, 1) });
            sel.push(1, nav(1, seq, 1));
            drain(&mut sel, &mut out);
        }
        assert_eq!(out.len() as u64, at + 20);
        sel.last_switch()
    }

    #[test]
    fn a_quality_switch_says_what_was_wrong_with_the_selected_lane() {
        let invalid = |seq| NavState {
            mode: NavMode::Invalid as u8,
            ..nav(0, seq, 1)
        };
        let switch = quality_switch(invalid, 300).expect("switched");
        assert_eq!(switch.reason, SwitchReason::Untrusted(Distrust::Invalid));
        assert_eq!(switch.at_seq, 300);
        assert_eq!(
            switch.to_string(),
            "lane 0 → 1 at seq 300: lane 0 invalid, lane 1 trusted"
        );
        // A lane that reset its solution at 300 (a takeover) is too young from there on.
        let switch = quality_switch(|seq| nav(0, seq, 300), 300).expect("switched");
        assert_eq!(
            switch.reason,
            SwitchReason::Untrusted(Distrust::Young { run: 0 })
        );
        assert_eq!(
            switch.to_string(),
            "lane 0 → 1 at seq 300: lane 0's solution too young (0 samples), lane 1 trusted"
        );
        let non_finite = |seq| NavState {
            quaternion: [f64::NAN; 4],
            ..nav(0, seq, 1)
        };
        let switch = quality_switch(non_finite, 300).expect("switched");
        assert_eq!(switch.reason, SwitchReason::Untrusted(Distrust::NonFinite));
        let mut counts = SwitchCounts::default();
        for r in [
            switch.reason,
            SwitchReason::Behind { ahead: 8 },
            SwitchReason::Silent {
                silent_ns: 1,
                ahead: 8,
            },
        ] {
            counts.count(r);
        }
        assert_eq!(
            (
                counts.untrusted,
                counts.behind,
                counts.silent,
                counts.total()
            ),
            (1, 1, 1, 3)
        );
    }

    #[test]
    fn a_lane_just_switched_to_is_not_left_for_being_late_by_less_than_the_dead_time() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        let mut lanes: [std::collections::VecDeque<NavState>; 2] = Default::default();
        // Lane 0 turns invalid at 300 for one sample: a quality switch to lane 1 at 300. Lane 1
        // then pauses (301..=308 published together, 301 7.4 ms late) while lane 0 is punctual:
        // lane 1 has delivered nothing yet since the switch and lane 0 is 8 samples ahead, but
        // that is no reason to switch back.
        for seq in 1..=600u64 {
            let mut s0 = stamped(0, seq, seq * MS + 100_000);
            if seq == 300 {
                s0.mode = NavMode::Invalid as u8;
            }
            lanes[0].push_back(s0);
            let ns1 = if (301..=308).contains(&seq) {
                308 * MS + 500_000 + seq
            } else {
                seq * MS
            };
            lanes[1].push_back(stamped(1, seq, ns1));
        }
        for now in (1..=6_100u64).map(|step| step * MS / 10) {
            consume(&mut sel, &mut lanes, now, &mut out);
        }
        assert_eq!(sel.switches(), 1);
        assert_eq!(
            sel.last_switch().map(|s| (s.to, s.at_seq, s.reason)),
            Some((1, 300, SwitchReason::Untrusted(Distrust::Invalid)))
        );
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=600).collect::<Vec<_>>());
        assert!(out[299..].iter().all(|o| o.1 == 1));
    }
}
