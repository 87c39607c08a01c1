//! The navigation output as the soak's consumer sees it: sequence gaps, the longest silence,
//! samples that were not navigating.

use std::time::{Duration, Instant};

use anyhow::Result;
use ipc_types::NavMode;
use rins_navigator::lanes::NavSubscriber;
use rins_watchdog::seq_gaps::SeqGaps;

#[derive(Debug, Default)]
pub struct NavWatch {
    /// Sequence numbers missing from the stream (the watchdog's own count).
    pub gaps: SeqGaps,
    /// When the newest sample arrived.
    pub last_at: Option<Instant>,
    pub samples: u64,
    /// Longest silence over the whole run.
    pub max_gap: Duration,
    /// Longest silence since [`Self::take_window_gap`] was last called.
    window_gap: Duration,
    navigated: bool,
    pub not_navigating: u64,
}

impl NavWatch {
    /// Takes every navigation sample that is due.
    pub fn drain(&mut self, nav: &mut NavSubscriber) -> Result<()> {
        while let Some(n) = nav.receive()? {
            self.observe(n.header.origin_seq, Instant::now());
            // A mode this build cannot read is no solution: counted as not navigating.
            self.observe_mode(NavMode::from_u8(n.mode).unwrap_or(NavMode::Aligning));
        }
        Ok(())
    }

    pub fn observe_mode(&mut self, mode: NavMode) {
        if mode == NavMode::Aligning {
            self.not_navigating += u64::from(self.navigated);
        } else {
            self.navigated = true;
        }
    }

    pub fn observe(&mut self, seq: u64, at: Instant) {
        self.gaps.observe(seq);
        if let Some(prev) = self.last_at {
            let gap = at.saturating_duration_since(prev);
            self.max_gap = self.max_gap.max(gap);
            self.window_gap = self.window_gap.max(gap);
        }
        self.last_at = Some(at);
        self.samples += 1;
    }

    /// The longest silence since the previous call, and a new window from now.
    pub fn take_window_gap(&mut self) -> Duration {
        std::mem::take(&mut self.window_gap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nav_watch_counts_missing_frames_and_the_longest_silence() {
        let t0 = Instant::now();
        let mut w = NavWatch::default();
        for (seq, ms) in [(10, 0), (11, 1), (15, 40), (16, 41), (14, 42), (17, 43)] {
            w.observe(seq, t0 + Duration::from_millis(ms));
        }
        // 12, 13, 14 missing at the jump; the late 14 does not undo the count nor move the seq back.
        assert_eq!(w.gaps.missing, 3);
        assert_eq!(w.samples, 6);
        assert_eq!(w.gaps.last(), Some(17));
        assert_eq!(w.max_gap, Duration::from_millis(39));
    }

    #[test]
    fn the_window_gap_starts_afresh_at_each_take() {
        let t0 = Instant::now();
        let mut w = NavWatch::default();
        w.observe(1, t0);
        w.observe(2, t0 + Duration::from_millis(30));
        assert_eq!(w.take_window_gap(), Duration::from_millis(30));
        w.observe(3, t0 + Duration::from_millis(35));
        assert_eq!(w.take_window_gap(), Duration::from_millis(5));
        assert_eq!(w.take_window_gap(), Duration::ZERO);
        assert_eq!(w.max_gap, Duration::from_millis(30));
    }

    #[test]
    fn aligning_counts_only_after_the_first_navigating_sample() {
        let mut w = NavWatch::default();
        for mode in [
            NavMode::Aligning,
            NavMode::Aligning,
            NavMode::Navigating,
            NavMode::Aligning,
        ] {
            w.observe_mode(mode);
        }
        assert_eq!(w.not_navigating, 1);
    }
}
