//! Choosing between the two navigator lanes: one contiguous navigation stream out of two.
//!
//! Both lanes run the same filter on the same fused IMU samples and stamp each solution with the
//! sequence number of its IMU sample, so the lanes' outputs are interchangeable sample by sample. The
//! selector delivers every sequence number once, in order, from the lane it has selected, and keeps
//! the other lane's samples that are ahead of the output so that a switch continues exactly at the
//! next sequence number: killing the selected lane loses no sample.
//!
//! Switching rule, built against the known failure modes of lane switching:
//! - **Dead lane** (liveness): the selected lane has delivered nothing beyond the output while the
//!   other lane is [`SelectorConfig::switch_lag`] samples ahead *and* has published for
//!   [`SelectorConfig::dead_after_ns`] since the selected lane's last sample (navigator publish
//!   times). One late sample is not a failure (no switch on a glitch): the lag has to build up
//!   first, which bounds the output gap to `switch_lag` sample periods. Nor is a burst: when a
//!   restarted fusion replays its history, or the serial line delivers what waited in it, both
//!   lanes work through hundreds of samples within a millisecond and one is briefly ahead; the
//!   selected lane is only dead when it has been silent for the time, not merely behind in count.
//!   A lane so far ahead that its pending samples would overflow ([`FORCE_SWITCH_PENDING`]) is
//!   taken regardless, since losing samples is worse than a switch.
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
//! Allocation-free after construction: each lane's pending samples sit in a fixed ring.

use std::collections::VecDeque;

use ipc_types::{NavMode, NavState, Stage};

/// Number of navigator lanes.
pub const LANES: usize = 2;

/// Pending samples kept per lane; more than any switch lag and than a burst that builds up while
/// the selected lane is silent for less than the dead time, so a switch always finds the next one.
const PENDING: usize = 512;

/// Pending samples of the other lane at which a silent selected lane is left at once.
pub const FORCE_SWITCH_PENDING: usize = PENDING / 2;

/// When the selector leaves a lane for the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SelectorConfig {
    /// Samples the other lane must be ahead of the output before the selected lane counts as dead.
    pub switch_lag: u64,
    /// And how long the other lane must have published since the selected lane's last sample, ns
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

/// Why the selector changed lanes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SwitchReason {
    /// The selected lane stopped delivering.
    Dead,
    /// The selected lane was aligning, invalid or too young, the other one trusted.
    Untrusted,
}

/// A change of the lane delivering, and why.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Switch {
    /// The lane left.
    pub from: usize,
    /// The lane delivering from now on.
    pub to: usize,
    /// Why the selector switched.
    pub reason: SwitchReason,
    /// Sequence number of the first sample delivered from the new lane.
    pub at_seq: u64,
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
    switches: u64,
    last_switch: Option<Switch>,
    filled: u64,
}

/// A solution the selector may choose for quality.
pub fn trusted(s: &NavState, settle: u64) -> bool {
    NavMode::from_u8(s.mode).is_some_and(NavMode::is_usable)
        && s.solution_start_seq != 0
        && s.header.origin_seq.saturating_sub(s.solution_start_seq) >= settle
        && s.quaternion.iter().all(|q| q.is_finite())
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
            switches: 0,
            last_switch: None,
            filled: 0,
        }
    }

    /// The lane delivering now.
    pub fn selected(&self) -> usize {
        self.selected
    }

    /// Lane changes since start.
    pub fn switches(&self) -> u64 {
        self.switches
    }

    /// The most recent lane change.
    pub fn last_switch(&self) -> Option<Switch> {
        self.last_switch
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
        }
        queue.push_back(sample);
    }

    /// The next sample of the output stream, or `None` until one is due.
    pub fn pop(&mut self) -> Option<NavState> {
        self.discard_delivered();
        let other = 1 - self.selected;
        if self.should_switch(other) {
            self.switch_to(other);
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

    fn should_switch(&self, other: usize) -> bool {
        let Some(candidate) = self.pending[other].front() else {
            return false;
        };
        let selected = &self.pending[self.selected];
        let Some(next) = selected.front() else {
            // Dead: nothing from the selected lane while the other has delivered `switch_lag`
            // samples ahead of the output. Counted in samples, not in sequence numbers, so that a
            // hole in the input (both lanes skip the same numbers) is no reason to switch.
            // Towards a lane that just reset, only after a longer silence: a selected lane that
            // is merely starved of CPU for a few milliseconds must not hand the output to it.
            let dead_after = if trusted(candidate, self.config.settle) {
                self.config.dead_after_ns
            } else {
                self.config.dead_after_untrusted_ns
            };
            let ahead = self.pending[other].len();
            return ahead >= FORCE_SWITCH_PENDING
                || (ahead as u64 >= self.config.switch_lag && self.silent_for(other, dead_after));
        };
        // Untrusted: only towards a trusted lane that has the next sample (not behind the
        // selected one), and not within the dwell time of the last switch.
        let dwelt = self
            .last_switch_seq
            .is_none_or(|at| next.header.origin_seq.saturating_sub(at) >= self.config.min_dwell);
        dwelt
            && !trusted(next, self.config.settle)
            && trusted(candidate, self.config.settle)
            && candidate.header.origin_seq <= next.header.origin_seq
    }

    /// The other lane has published for `dead_after` ns since the selected lane's last sample.
    fn silent_for(&self, other: usize, dead_after: u64) -> bool {
        let newest = self.pending[other]
            .back()
            .map_or(0, |s| s.header.stage_ns(Stage::Navigator));
        if self.selected_published_ns == 0 || newest == 0 {
            return true;
        }
        newest.saturating_sub(self.selected_published_ns) >= dead_after
    }

    fn switch_to(&mut self, lane: usize) {
        let at_seq = self.pending[lane]
            .front()
            .map_or(0, |s| s.header.origin_seq);
        let reason = if self.pending[self.selected].is_empty() {
            SwitchReason::Dead
        } else {
            SwitchReason::Untrusted
        };
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
        self.switches += 1;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SETTLE: u64 = 100;

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
    fn nav(lane: u8, seq: u64, start: u64) -> NavState {
        let mut s = NavState {
            mode: NavMode::Navigating as u8,
            lane,
            solution_start_seq: start,
            ..NavState::default()
        };
        s.header.origin_seq = seq;
        s
    }

    fn aligning(lane: u8, seq: u64) -> NavState {
        let mut s = nav(lane, seq, 0);
        s.mode = NavMode::Aligning as u8;
        s
    }

    fn drain(sel: &mut LaneSelector, out: &mut Vec<(u64, u8)>) {
        while let Some(s) = sel.pop() {
            out.push((s.header.origin_seq, s.lane));
        }
    }

    #[test]
    fn only_a_settled_usable_mode_is_trusted() {
        let settled = nav(0, 1 + SETTLE, 1);
        assert!(trusted(&settled, SETTLE));
        let coasting = NavState {
            mode: NavMode::Coasting as u8,
            ..settled
        };
        assert!(trusted(&coasting, SETTLE));
        // Aligning, invalid, or a mode this build cannot read: no usable solution.
        for mode in [NavMode::Aligning as u8, NavMode::Invalid as u8, 4, u8::MAX] {
            assert!(
                !trusted(&NavState { mode, ..settled }, SETTLE),
                "mode {mode}"
            );
        }
        assert!(!trusted(&nav(0, SETTLE, 1), SETTLE));
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
                reason: SwitchReason::Dead,
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
        // Lane 1 publishes 208 at 208 ms, 8 ms after lane 0's last sample: the switch.
        assert_eq!(stall, 7);
        assert_eq!(sel.last_switch().map(|s| (s.to, s.at_seq)), Some((1, 201)));
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

    #[test]
    fn a_burst_that_would_overflow_the_pending_samples_switches_at_once() {
        let mut sel = LaneSelector::new(cfg());
        let mut out = Vec::new();
        for seq in 1..=200 {
            sel.push(0, stamped(0, seq, seq * MS));
            sel.push(1, stamped(1, seq, seq * MS));
            drain(&mut sel, &mut out);
        }
        // Lane 0 is gone; lane 1 replays 2 × PENDING samples within a millisecond.
        for seq in 201..=200 + 2 * PENDING as u64 {
            sel.push(1, stamped(1, seq, 200 * MS + seq));
            drain(&mut sel, &mut out);
        }
        assert_eq!(sel.last_switch().map(|s| (s.to, s.at_seq)), Some((1, 201)));
        let seqs: Vec<u64> = out.iter().map(|o| o.0).collect();
        assert_eq!(seqs, (1..=200 + 2 * PENDING as u64).collect::<Vec<_>>());
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
            Some((1, SwitchReason::Untrusted, 500))
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
            Some((0, SwitchReason::Untrusted, 251))
        );
        assert_eq!(out.len(), 400);
    }
}
