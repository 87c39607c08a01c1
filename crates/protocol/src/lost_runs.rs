//! The last few runs of sequence numbers counted lost, so that a frame arriving too far behind the
//! newest for [`crate::seq_window`] to remember can still be told: a number in a run was counted
//! lost and is now recovered; any other was received before (a duplicate) or never counted.
//! Fixed size, no allocation: older runs are forgotten, and a frame of theirs is late without
//! recovery.

/// Runs remembered: a few outages' worth.
const RUNS: usize = 8;

/// Extended numbers counted lost, as runs `[from, to)` (empty when `from == to`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct LostRuns {
    runs: [(u64, u64); RUNS],
    /// The slot written next (the oldest).
    next: usize,
}

impl LostRuns {
    /// The numbers `from..to` were counted lost.
    pub fn add(&mut self, from: u64, to: u64) {
        if from < to {
            self.runs[self.next] = (from, to);
            self.next = (self.next + 1) % RUNS;
        }
    }

    /// Takes `seq` out of the runs; whether it was counted lost (and no longer is).
    pub fn recover(&mut self, seq: u64) -> bool {
        let Some(i) = self.runs.iter().position(|&(a, b)| a <= seq && seq < b) else {
            return false;
        };
        let (a, b) = self.runs[i];
        if seq == a {
            self.runs[i].0 = a + 1;
        } else if seq + 1 == b {
            self.runs[i].1 = seq;
        } else {
            // Split: the upper part takes the oldest slot.
            self.runs[i].1 = seq;
            self.add(seq + 1, b);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_is_recovered_once_and_runs_split_around_it() {
        let mut r = LostRuns::default();
        r.add(10, 20);
        assert!(r.recover(15));
        assert!(!r.recover(15));
        assert!(r.recover(10) && r.recover(19) && r.recover(14) && r.recover(16));
        assert!(!r.recover(20) && !r.recover(9));
    }

    #[test]
    fn the_oldest_runs_are_forgotten() {
        let mut r = LostRuns::default();
        for i in 0..=RUNS as u64 {
            r.add(i * 10, i * 10 + 2);
        }
        assert!(!r.recover(0));
        assert!(r.recover(RUNS as u64 * 10));
    }
}
