//! When the standby lane reads its input in batches instead of sample by sample.
//!
//! A hot standby integrates every fused IMU sample, so that it can serve the moment the primary
//! fails; it need not integrate each one the instant it is published while nobody reads its
//! output. Woken once per sample it costs a wake-up per frame, and on a small machine it competes
//! for a CPU with the primary it stands by for. So while the primary lane is alive, current and
//! trusted, the standby sleeps a batch period (a few tens of samples, at most
//! [`MAX_BATCH_PERIOD`]) and then integrates what queued meanwhile: one wake-up per batch, every
//! sample still integrated, in order.
//!
//! It serves — waits for each sample as the primary does — as soon as the primary is not current
//! (its newest output is [`LAG_PERIOD`] worth of samples behind the newest input: killed, hung or
//! starved) or less trusted than the standby (the primary aligning, invalid or just restarted
//! while the standby's own solution is trusted: the primary then takes the standby's solution
//! over and the consumers follow the standby). While both lanes align, neither serves anything
//! worth a prompt copy, and the standby batches. It returns to batches only after the primary has
//! been current and at least as trusted for [`RESUME_SAMPLES`] inputs in a row, so a primary that
//! stutters does not make the standby flip back and forth.
//!
//! A primary that takes the standby's solution over skips the samples the standby covered, and
//! the standby may have published those in a batch: consumers take the other lane up to the
//! selected lane's next sample before they deliver it, so the batch fills the hole.
//!
//! What a consumer sees: the standby's samples arrive a batch late while the primary serves; none
//! is lost. When the primary dies, the standby notices at its next batch (within one or two batch
//! periods), serves from then on and publishes its backlog at once; the lane selector in each
//! consumer moves to it by its dead-lane rule with every sequence number in order. When the
//! standby goes back to batches while a consumer follows it (after the primary restarted and
//! settled), its silence between batches moves that consumer back to the prompt lane by the same
//! rule, again losing nothing.

use std::time::Duration;

use ipc_types::NavState;

use crate::lanes::trust::distrust;

/// Longest batch: a takeover waits for at most two of them.
pub const MAX_BATCH_PERIOD: Duration = Duration::from_millis(20);

/// Samples per batch at high rates: the listener keeps one notification per sample until the
/// batch is read, and these stay few.
const BATCH_SAMPLES: f64 = 32.0;

/// How far behind the newest input the primary's newest output may be and still count as
/// current, as time.
pub const LAG_PERIOD: Duration = Duration::from_millis(8);

/// Inputs in a row with the primary current and trusted before the standby batches again.
pub const RESUME_SAMPLES: u64 = 1000;

/// See the module documentation.
#[derive(Debug, Clone)]
pub struct StandbyPacer {
    period: Duration,
    lag_samples: u64,
    settle: u64,
    peer_seq: u64,
    peer_trusted: bool,
    own_trusted: bool,
    input_seq: u64,
    current_since: Option<u64>,
    batching: bool,
}

impl StandbyPacer {
    /// A pacer for a block at `rate_hz` (an unusable rate counts as 1 kHz); `settle` is the lane
    /// selector's settling time in samples, the trust the primary must have.
    pub fn new(rate_hz: f64, settle: u64) -> Self {
        let rate = if rate_hz.is_finite() && rate_hz > 0.0 {
            rate_hz
        } else {
            1000.0
        };
        let period = Duration::from_secs_f64(BATCH_SAMPLES / rate).min(MAX_BATCH_PERIOD);
        let lag_samples = (LAG_PERIOD.as_secs_f64() * rate).ceil().max(4.0) as u64;
        Self {
            period,
            lag_samples,
            settle,
            peer_seq: 0,
            peer_trusted: false,
            own_trusted: false,
            input_seq: 0,
            current_since: None,
            // At the start the standby batches until the primary proves not current: the
            // hysteresis is for a primary that failed, not for one that has not had the chance.
            batching: true,
        }
    }

    /// One output of the primary lane.
    pub fn peer(&mut self, s: &NavState) {
        if s.header.origin_seq >= self.peer_seq {
            self.peer_seq = s.header.origin_seq;
            self.peer_trusted = distrust(s, self.settle).is_none();
        }
    }

    /// One output of this lane.
    pub fn own(&mut self, s: &NavState) {
        self.own_trusted = distrust(s, self.settle).is_none();
    }

    /// One fused IMU sample taken in by this lane.
    pub fn input(&mut self, seq: u64) {
        self.input_seq = self.input_seq.max(seq);
        let current = (self.peer_trusted || !self.own_trusted)
            && self.peer_seq + self.lag_samples >= self.input_seq;
        if !current {
            self.batching = false;
            self.current_since = None;
            return;
        }
        let since = *self.current_since.get_or_insert(self.input_seq);
        if self.input_seq.saturating_sub(since) >= RESUME_SAMPLES {
            self.batching = true;
        }
    }

    /// How long to sleep before reading the input, while batching; `None` while serving.
    pub fn batch_period(&self) -> Option<Duration> {
        self.batching.then_some(self.period)
    }

    /// Whether the standby reads in batches now.
    pub fn batching(&self) -> bool {
        self.batching
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::NavMode;

    fn peer(seq: u64, mode: NavMode) -> NavState {
        let mut s = NavState {
            mode: mode as u8,
            solution_start_seq: 1,
            ..NavState::default()
        };
        s.header.origin_seq = seq;
        s
    }

    /// Both lanes advancing together for `n` samples from `from`.
    fn together(p: &mut StandbyPacer, from: u64, n: u64) {
        for seq in from..from + n {
            p.peer(&peer(seq, NavMode::Navigating));
            p.input(seq);
        }
    }

    #[test]
    fn batches_from_the_start_and_after_a_failure_once_the_primary_is_back_for_the_resume_time() {
        let mut p = StandbyPacer::new(1000.0, 100);
        // Samples 200.. : the primary's solution settled (100 samples) from the first on.
        together(&mut p, 200, 1);
        assert_eq!(p.batch_period(), Some(MAX_BATCH_PERIOD));
        // The primary falls 9 samples behind: the standby serves.
        p.input(210);
        assert_eq!(p.batch_period(), None);
        together(&mut p, 211, RESUME_SAMPLES);
        assert_eq!(p.batch_period(), None);
        together(&mut p, RESUME_SAMPLES + 211, 1);
        assert_eq!(p.batch_period(), Some(MAX_BATCH_PERIOD));
    }

    #[test]
    fn a_primary_that_falls_behind_makes_the_standby_serve_at_once() {
        let mut p = StandbyPacer::new(1000.0, 100);
        together(&mut p, 200, 2 * RESUME_SAMPLES);
        assert!(p.batching());
        let last = 200 + 2 * RESUME_SAMPLES - 1;
        // The primary stops; a batch of inputs arrives: 8 samples behind are allowed at 1 kHz.
        for seq in last + 1..=last + 8 {
            p.input(seq);
        }
        assert!(p.batching(), "8 samples behind is still current at 1 kHz");
        p.input(last + 9);
        assert_eq!(p.batch_period(), None);
    }

    #[test]
    fn a_primary_less_trusted_than_the_standby_is_not_stood_by_for() {
        let mut p = StandbyPacer::new(1000.0, 100);
        p.own(&peer(200, NavMode::Navigating));
        for seq in 200..3000 {
            p.peer(&peer(seq, NavMode::Aligning));
            p.input(seq);
        }
        assert!(
            !p.batching(),
            "a primary that aligns takes the standby's solution over"
        );
        together(&mut p, 3000, RESUME_SAMPLES + 1);
        assert!(p.batching());
        // A primary whose solution is younger than the settling time (it restarted and took the
        // standby's solution over) is not trusted either.
        let mut young = peer(5000, NavMode::Navigating);
        young.solution_start_seq = 4950;
        p.peer(&young);
        p.input(5000);
        assert!(!p.batching());
    }

    #[test]
    fn while_both_lanes_align_the_standby_batches() {
        let mut p = StandbyPacer::new(1000.0, 100);
        p.own(&peer(1, NavMode::Aligning));
        for seq in 1..=RESUME_SAMPLES + 1 {
            p.peer(&peer(seq, NavMode::Aligning));
            p.input(seq);
        }
        assert!(p.batching());
        // The standby's own solution becomes trusted first: it serves until the primary's is.
        p.own(&peer(RESUME_SAMPLES + 2, NavMode::Navigating));
        p.input(RESUME_SAMPLES + 2);
        assert!(!p.batching());
    }

    #[test]
    fn the_batch_holds_a_few_tens_of_samples_at_any_rate() {
        for (rate, period_ms) in [(100.0, 20.0), (1000.0, 20.0), (8000.0, 4.0), (16000.0, 2.0)] {
            let p = StandbyPacer::new(rate, 100);
            assert!(
                (p.period.as_secs_f64() * 1e3 - period_ms).abs() < 1e-9,
                "{rate} Hz"
            );
        }
        // A rate that makes no sense counts as 1 kHz rather than a zero or endless batch.
        assert_eq!(StandbyPacer::new(f64::NAN, 1).period, MAX_BATCH_PERIOD);
        assert_eq!(StandbyPacer::new(0.0, 1).period, MAX_BATCH_PERIOD);
    }
}
