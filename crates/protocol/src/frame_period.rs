//! One frame type's period, learnt on the receive clock.
//!
//! Frames arrive in bursts (every frame a read completes carries that read's receive time), so the
//! period is an average over many frames: the receive time of a block of at least a second and 64
//! frames divided by the sequence numbers it advanced (lost frames included, so losses do not
//! lengthen it). A block that begins or ends in a backlog (frames read late, all at once, after
//! the process was held up) is off by the backlog's lateness, so the period is the median of the
//! last [`BLOCKS`] blocks, known once [`MIN_BLOCKS`] are complete: one stall spoils at most two.
//! The first second after the first frame is skipped: it may be a backlog the kernel held while no
//! process read the line. A block in which the numbering was re-based is discarded.

/// Receive time skipped after the first frame.
pub const WARMUP_NS: u64 = 1_000_000_000;
/// Shortest block, receive time.
const BLOCK_NS: u64 = 1_000_000_000;
/// Fewest sequence steps in a block.
const BLOCK_MIN_STEPS: u64 = 64;
/// Blocks the median is taken over, and how many are needed for a period.
const BLOCKS: usize = 5;
const MIN_BLOCKS: usize = 3;

/// The learnt period of one frame type on the receive clock (see the module documentation); unknown
/// until enough blocks are complete.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FramePeriod {
    first_rx_ns: Option<u64>,
    /// Extended number and receive time where the current block began.
    block: Option<(u64, u64)>,
    /// Period of the last blocks, ns, the newest at `(next + BLOCKS - 1) % BLOCKS`.
    estimates: [u64; BLOCKS],
    next: usize,
    complete: usize,
    period_ns: Option<u64>,
}

impl FramePeriod {
    /// Takes a frame delivered under extended number `seq`, received at `rx_ns`.
    pub fn observe(&mut self, seq: u64, rx_ns: u64) {
        let first = *self.first_rx_ns.get_or_insert(rx_ns);
        if rx_ns.saturating_sub(first) < WARMUP_NS {
            return;
        }
        let Some((seq0, rx0)) = self.block else {
            self.block = Some((seq, rx_ns));
            return;
        };
        let (steps, elapsed) = (seq.saturating_sub(seq0), rx_ns.saturating_sub(rx0));
        if steps >= BLOCK_MIN_STEPS && elapsed >= BLOCK_NS {
            self.estimates[self.next] = (elapsed / steps).max(1);
            self.next = (self.next + 1) % BLOCKS;
            self.complete = (self.complete + 1).min(BLOCKS);
            self.block = Some((seq, rx_ns));
            if self.complete >= MIN_BLOCKS {
                let mut sorted = self.estimates;
                let recent = &mut sorted[..self.complete];
                recent.sort_unstable();
                self.period_ns = Some(recent[recent.len() / 2]);
            }
        }
    }

    /// The numbering was re-based: the current block no longer measures time.
    pub fn discard_block(&mut self) {
        self.block = None;
    }

    /// The learnt period, ns; `None` until [`MIN_BLOCKS`] blocks are complete.
    pub fn period_ns(&self) -> Option<u64> {
        self.period_ns
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: u64 = 1_000_000;

    #[test]
    fn learnt_from_bursts_after_the_warm_up() {
        let mut p = FramePeriod::default();
        // A backlog of 500 frames read at once, then 1 kHz frames in reads of 4.
        for seq in 0..500 {
            p.observe(seq, 0);
        }
        let mut seq = 500;
        while p.period_ns().is_none() {
            seq += 1;
            p.observe(seq, (seq - 500) / 4 * 4 * MS);
            assert!(seq < 10_000, "period not learnt");
        }
        // Warm-up (1 s) and three blocks (1 s each).
        assert!((4_500..4_510).contains(&seq), "{seq}");
        assert_eq!(p.period_ns(), Some(MS));
    }

    #[test]
    fn a_stall_does_not_move_it() {
        let mut p = FramePeriod::default();
        for seq in 0..6_000 {
            p.observe(seq, seq * MS);
        }
        // Stalled 3 s: frames 6 000..7 000 read late, at once; 7 000..9 000 dropped by the kernel.
        for seq in 6_000..7_000 {
            p.observe(seq, 9_000 * MS);
        }
        for seq in 9_000..20_000 {
            p.observe(seq, seq * MS);
            assert_eq!(p.period_ns(), Some(MS), "{seq}");
        }
    }

    #[test]
    fn lost_frames_do_not_lengthen_it_and_a_re_based_block_is_discarded() {
        let mut p = FramePeriod::default();
        // Every other frame lost, 50 Hz.
        for k in 0..200u64 {
            p.observe(2 * k, k * 40 * MS);
        }
        assert_eq!(p.period_ns(), Some(20 * MS));
        p.discard_block();
        p.observe(1_000_000, 200 * 40 * MS);
        p.observe(1_000_100, 210 * 40 * MS);
        assert_eq!(p.period_ns(), Some(20 * MS));
    }
}
