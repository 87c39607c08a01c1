//! Stationary detection and the per-channel reference that isolates a parity alarm the parity
//! space cannot isolate (N = 4, or twin channels).
//!
//! **Detection.** The fused rate and specific force are summarised over consecutive blocks of
//! `window` samples (running sums, no sample buffer). A block is stationary when every axis'
//! standard deviation is below `rate_spread` / `force_spread` and the mean rate is below
//! `max_rate` (a steady turn is not "stationary"). The vehicle counts as stationary now when the
//! last completed block was and the current partial block has not (yet) contradicted it.
//!
//! **Reference.** While stationary, each channel's mean over a block is `h_i·x_ref` plus the
//! channel's own residual bias — the per-channel form of the design's `h_i·x_ref` that also removes
//! calibration residuals. A block becomes the reference when it was stationary, no fault was
//! declared during it, the active set did not change, and its mean test statistic was consistent
//! with noise (`mean T ≤ m + 5·√(2m/W)`, which also keeps a slowly growing, still undetected
//! fault out of the reference). For gyros the reference (zero rate + residual bias) holds in any
//! later stationary period; for accelerometers only while the vehicle has stayed stationary since
//! (a new attitude changes gravity's projection).
//!
//! **Isolation.** When the parity test fires while stationary, the evidence is each channel's
//! mean over the last few samples `ē_i`; its distance from the reference in standard errors is
//! `r_i = |ē_i − m_i| / (σ_i·√(1/n_e + 1/W))`. The channel with the largest `r_i` is isolated
//! only when it is a parity candidate and dominates: `r_best ≥ ratio · max(r_second, 1)`.
//! Otherwise the fault stays detected-but-unisolated.

use super::persistence::MAX_PERSISTENCE_WINDOW;
use crate::geometry::MAX_CHANNELS;

/// Thresholds of the stationary detector (validated by the configuration).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationarySettings {
    /// Block length, samples.
    pub window: u32,
    /// Largest per-axis standard deviation of the fused rate, rad/s.
    pub rate_spread: f64,
    /// Largest per-axis standard deviation of the fused specific force, m/s².
    pub force_spread: f64,
    /// Largest norm of the mean fused rate, rad/s.
    pub max_rate: f64,
}

/// Fewest samples of a partial block that can contradict the last block's verdict.
const MIN_PARTIAL: u32 = 10;

/// Block statistics of the fused rate and specific force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StationaryDetector {
    settings: StationarySettings,
    count: u32,
    all_valid: bool,
    sum: [f64; 6],
    sum_sq: [f64; 6],
    last_block: bool,
}

impl StationaryDetector {
    /// A detector with the given thresholds; not stationary until a first block completes.
    pub fn new(settings: StationarySettings) -> Self {
        Self {
            settings,
            count: 0,
            all_valid: true,
            sum: [0.0; 6],
            sum_sq: [0.0; 6],
            last_block: false,
        }
    }

    /// Adds one fused sample (`valid` false when either sensor type had no solution). Returns the
    /// verdict of the block that this sample completes, if any.
    pub fn push(&mut self, rate: &[f64; 3], force: &[f64; 3], valid: bool) -> Option<bool> {
        self.all_valid &= valid;
        for (k, v) in rate.iter().chain(force).enumerate() {
            self.sum[k] += v;
            self.sum_sq[k] += v * v;
        }
        self.count += 1;
        if self.count < self.settings.window {
            return None;
        }
        let verdict = self.all_valid && self.block_ok();
        self.last_block = verdict;
        self.count = 0;
        self.all_valid = true;
        self.sum = [0.0; 6];
        self.sum_sq = [0.0; 6];
        Some(verdict)
    }

    /// The last completed block was stationary and the current one has not contradicted it.
    pub fn is_stationary(&self) -> bool {
        self.last_block && (self.count < MIN_PARTIAL || (self.all_valid && self.block_ok()))
    }

    fn block_ok(&self) -> bool {
        let n = f64::from(self.count);
        let spread = |k: usize| {
            let var = (self.sum_sq[k] - self.sum[k] * self.sum[k] / n) / (n - 1.0);
            var.max(0.0).sqrt()
        };
        let s = &self.settings;
        let mean_rate2: f64 = (0..3).map(|k| (self.sum[k] / n).powi(2)).sum();
        (0..3).all(|k| spread(k) <= s.rate_spread)
            && (3..6).all(|k| spread(k) <= s.force_spread)
            && mean_rate2.sqrt() <= s.max_rate
    }
}

/// The stationary reference of one sensor type and the recent samples that are compared with it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelReference {
    /// Gyros: the reference (zero rate) holds in every stationary period.
    holds_across_periods: bool,
    window: u32,
    block_sum: [f64; MAX_CHANNELS],
    block_count: u32,
    block_mask: u32,
    block_clean: bool,
    block_statistic_sum: f64,
    mean: [f64; MAX_CHANNELS],
    mask: u32,
    samples: u32,
    valid: bool,
    recent: [[f64; MAX_CHANNELS]; MAX_PERSISTENCE_WINDOW],
    recent_capacity: usize,
    recent_len: usize,
    recent_pos: usize,
    /// Exponentially weighted mean of each channel (weight `smooth_alpha`; 0: none kept): the
    /// evidence for a fault only the windowed parity mean sees, too small for `recent`.
    smooth: [f64; MAX_CHANNELS],
    smooth_alpha: f64,
    /// Samples in `smooth` since the active set last changed.
    smooth_len: u32,
}

impl ChannelReference {
    /// A reference over blocks of `window` samples with evidence over the last `evidence`
    /// samples (≤ 16), and over an exponentially weighted mean of about `smoothing` samples (0:
    /// none). `holds_across_periods`: true for gyros.
    pub fn new(window: u32, evidence: usize, smoothing: u32, holds_across_periods: bool) -> Self {
        Self {
            holds_across_periods,
            window,
            block_sum: [0.0; MAX_CHANNELS],
            block_count: 0,
            block_mask: 0,
            block_clean: true,
            block_statistic_sum: 0.0,
            mean: [0.0; MAX_CHANNELS],
            mask: 0,
            samples: 0,
            valid: false,
            recent: [[0.0; MAX_CHANNELS]; MAX_PERSISTENCE_WINDOW],
            recent_capacity: evidence.clamp(1, MAX_PERSISTENCE_WINDOW),
            recent_len: 0,
            recent_pos: 0,
            smooth: [0.0; MAX_CHANNELS],
            smooth_alpha: if smoothing == 0 {
                0.0
            } else {
                2.0 / (f64::from(smoothing) + 1.0)
            },
            smooth_len: 0,
        }
    }

    /// Adds one sample of the active channels `active` with its test statistic `t`; `clean`
    /// false while a fault is declared.
    pub fn push(&mut self, z: &[f64; MAX_CHANNELS], active: u32, t: f64, clean: bool) {
        if active != self.block_mask {
            // A block must see one active set from its first sample to its last.
            self.block_clean &= self.block_count == 0;
            self.block_mask = active;
        }
        self.block_clean &= clean;
        for (i, s) in self.block_sum.iter_mut().enumerate() {
            if active & (1 << i) != 0 {
                *s += z[i];
            }
        }
        self.block_count += 1;
        self.block_statistic_sum += t;
        self.recent[self.recent_pos] = *z;
        self.recent_pos = (self.recent_pos + 1) % self.recent_capacity;
        self.recent_len = (self.recent_len + 1).min(self.recent_capacity);
        if self.smooth_alpha > 0.0 {
            let a = if self.smooth_len == 0 {
                1.0
            } else {
                self.smooth_alpha
            };
            for (i, m) in self.smooth.iter_mut().enumerate() {
                if active & (1 << i) != 0 && z[i].is_finite() {
                    *m += a * (z[i] - *m);
                }
            }
            self.smooth_len = self.smooth_len.saturating_add(1);
        }
    }

    /// Closes the block that the stationary detector just judged; `parity_dimension` of the
    /// active set during the block (for the noise-consistency check).
    pub fn end_block(&mut self, stationary: bool, parity_dimension: usize) {
        if !stationary && !self.holds_across_periods {
            self.valid = false;
        }
        let n = f64::from(self.block_count);
        let m = parity_dimension as f64;
        let consistent = self.block_statistic_sum / n <= m + 5.0 * (2.0 * m / n).sqrt();
        if stationary && self.block_clean && self.block_count == self.window && consistent {
            for (i, (mean, sum)) in self.mean.iter_mut().zip(&self.block_sum).enumerate() {
                *mean = if self.block_mask & (1 << i) != 0 {
                    sum / n
                } else {
                    0.0
                };
            }
            self.mask = self.block_mask;
            self.samples = self.block_count;
            self.valid = true;
        }
        self.block_sum = [0.0; MAX_CHANNELS];
        self.block_count = 0;
        self.block_clean = true;
        self.block_statistic_sum = 0.0;
    }

    /// Subtracts `delta` from every channel's values held so far (reference, current block,
    /// recent samples): the input values are shifted by `−delta` from now on.
    pub fn shift(&mut self, delta: &[f64; MAX_CHANNELS]) {
        let block = f64::from(self.block_count);
        for (i, d) in delta.iter().enumerate() {
            if self.mask & (1 << i) != 0 {
                self.mean[i] -= d;
            }
            if self.block_mask & (1 << i) != 0 {
                self.block_sum[i] -= block * d;
            }
        }
        for z in &mut self.recent[..self.recent_len] {
            for (v, d) in z.iter_mut().zip(delta) {
                *v -= d;
            }
        }
        for (m, d) in self.smooth.iter_mut().zip(delta) {
            *m -= d;
        }
    }

    /// Forgets the recent samples (after the active set changed).
    pub fn clear_recent(&mut self) {
        self.recent_len = 0;
        self.recent_pos = 0;
        self.smooth_len = 0;
    }

    /// A reference is held (it may still be unusable if the vehicle is not stationary now).
    pub fn is_valid(&self) -> bool {
        self.valid
    }

    /// The channel among `candidates` that clearly departs from the reference, judged over the
    /// active channels `active` with noise σ² `variances` on the last few samples, or `None`.
    pub fn isolate(
        &self,
        candidates: u32,
        active: u32,
        variances: &[f64; MAX_CHANNELS],
        ratio: f64,
    ) -> Option<usize> {
        if self.recent_len == 0 {
            return None;
        }
        let ne = self.recent_len as f64;
        let recent = &self.recent[..self.recent_len];
        self.pick(candidates, active, variances, ratio, 1.0 / ne, |i| {
            recent.iter().map(|z| z[i]).sum::<f64>() / ne
        })
    }

    /// As [`Self::isolate`], judged on the exponentially weighted mean of each channel: for a
    /// fault too small for the last few samples. `None` until the mean has seen about its length
    /// since the active set last changed.
    pub fn isolate_smoothed(
        &self,
        candidates: u32,
        active: u32,
        variances: &[f64; MAX_CHANNELS],
        ratio: f64,
    ) -> Option<usize> {
        let a = self.smooth_alpha;
        if a <= 0.0 || f64::from(self.smooth_len) < 2.0 / a {
            return None;
        }
        // The weighted mean's variance, in units of one sample's.
        let share = a / (2.0 - a);
        self.pick(candidates, active, variances, ratio, share, |i| {
            self.smooth[i]
        })
    }

    /// The channel whose `mean` (a variance of `share` of one sample's) departs from the
    /// reference by `ratio` times more than any other's, if it is a candidate.
    fn pick(
        &self,
        candidates: u32,
        active: u32,
        variances: &[f64; MAX_CHANNELS],
        ratio: f64,
        share: f64,
        mean: impl Fn(usize) -> f64,
    ) -> Option<usize> {
        if !self.valid {
            return None;
        }
        let judged = active & self.mask;
        let scale = share + 1.0 / f64::from(self.samples.max(1));
        let mut best: Option<(usize, f64)> = None;
        let mut second = 0.0_f64;
        for i in (0..MAX_CHANNELS).filter(|i| judged & (1 << i) != 0) {
            let r = (mean(i) - self.mean[i]).abs() / (variances[i] * scale).sqrt();
            if !r.is_finite() {
                return None;
            }
            match best {
                Some((_, b)) if r <= b => second = second.max(r),
                Some((_, b)) => {
                    second = second.max(b);
                    best = Some((i, r));
                }
                None => best = Some((i, r)),
            }
        }
        let (winner, r) = best?;
        (candidates & (1 << winner) != 0 && r >= ratio * second.max(1.0)).then_some(winner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> StationarySettings {
        StationarySettings {
            window: 100,
            rate_spread: 0.02,
            force_spread: 0.2,
            max_rate: 0.05,
        }
    }

    #[test]
    fn blocks_judge_spread_and_mean_rate() {
        let mut d = StationaryDetector::new(settings());
        assert!(!d.is_stationary());
        let f = [0.0, 0.0, -9.8];
        // Alternating ±0.01 rad/s: σ ≈ 0.01 < 0.02 → stationary.
        let mut verdicts = vec![];
        for k in 0..200 {
            let r = if k % 2 == 0 { 0.01 } else { -0.01 };
            verdicts.extend(d.push(&[r, 0.0, 0.0], &f, true));
        }
        assert_eq!(verdicts, vec![true, true]);
        assert!(d.is_stationary());
        // ±0.03: spread too large; the partial block already says so after 10 samples.
        for k in 0..10 {
            let r = if k % 2 == 0 { 0.03 } else { -0.03 };
            assert_eq!(d.push(&[r, 0.0, 0.0], &f, true), None);
        }
        assert!(!d.is_stationary());
        // A steady turn of 0.1 rad/s has no spread but is not stationary.
        let mut d = StationaryDetector::new(settings());
        let v: Vec<_> = (0..100)
            .filter_map(|_| d.push(&[0.0, 0.0, 0.1], &f, true))
            .collect();
        assert_eq!(v, vec![false]);
        // An invalid sample spoils its block.
        let mut d = StationaryDetector::new(settings());
        let v: Vec<_> = (0..100)
            .filter_map(|k| d.push(&[0.0; 3], &f, k != 50))
            .collect();
        assert_eq!(v, vec![false]);
    }

    #[test]
    fn reference_isolates_the_departing_channel_only_when_it_dominates() {
        let var = [1.0; MAX_CHANNELS];
        let mut r = ChannelReference::new(100, 5, 0, false);
        let base = {
            let mut z = [0.0; MAX_CHANNELS];
            z[..4].copy_from_slice(&[1.0, 2.0, 3.0, 4.0]);
            z
        };
        for _ in 0..100 {
            r.push(&base, 0b1111, 1.0, true);
        }
        r.end_block(true, 1);
        assert!(r.is_valid());
        let mut faulty = base;
        faulty[2] += 10.0;
        for _ in 0..5 {
            r.push(&faulty, 0b1111, 1.0, true);
        }
        assert_eq!(r.isolate(0b1111, 0b1111, &var, 3.0), Some(2));
        // Not a candidate → not isolated.
        assert_eq!(r.isolate(0b1011, 0b1111, &var, 3.0), None);
        // Two channels departing alike → no dominance.
        let mut two = faulty;
        two[0] += 10.0;
        for _ in 0..5 {
            r.push(&two, 0b1111, 1.0, true);
        }
        assert_eq!(r.isolate(0b1111, 0b1111, &var, 3.0), None);
        // Accelerometer reference is lost when the vehicle moves.
        r.end_block(false, 1);
        assert!(!r.is_valid());
    }

    /// A fault of one noise σ: on the last five samples any channel's noise passes for it; on
    /// the weighted mean over 200 samples only the faulty channel stands out.
    #[test]
    fn the_smoothed_evidence_isolates_a_one_sigma_fault_that_five_samples_cannot() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let var = [1.0; MAX_CHANNELS];
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let mut noisy = |offset: [f64; 4]| {
            let mut z = [0.0; MAX_CHANNELS];
            for (v, o) in z.iter_mut().zip(offset) {
                let n: f64 = StandardNormal.sample(&mut rng);
                *v = o + n;
            }
            z
        };
        let mut r = ChannelReference::new(1000, 5, 200, true);
        for _ in 0..1000 {
            r.push(&noisy([0.0; 4]), 0b1111, 1.0, true);
        }
        r.end_block(true, 1);
        // Too little evidence right after the active set changed.
        r.clear_recent();
        assert_eq!(r.isolate_smoothed(0b1111, 0b1111, &var, 3.0), None);
        let (mut smoothed, mut wrong_recent) = (Vec::new(), 0);
        for _ in 0..2000 {
            r.push(&noisy([0.0, 0.0, 1.0, 0.0]), 0b1111, 1.0, true);
            if let Some(ch) = r.isolate_smoothed(0b1111, 0b1111, &var, 3.0) {
                smoothed.push(ch);
            }
            if r.isolate(0b1111, 0b1111, &var, 3.0)
                .is_some_and(|ch| ch != 2)
            {
                wrong_recent += 1;
            }
        }
        assert!(!smoothed.is_empty(), "the smoothed mean found nothing");
        assert!(smoothed.iter().all(|&ch| ch == 2), "{smoothed:?}");
        // The five-sample judgement blames a wrong channel now and then: what the smoothed
        // evidence is for.
        assert!(wrong_recent > 0);
    }
}
