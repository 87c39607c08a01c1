//! Recovery of a sensor type that has lost its solution: re-test of its latched exclusions.
//!
//! Exclusions latch (see [`super::monitor`]): a channel that failed once is not trusted again on its
//! own word. That rule protects a solution that still exists; once fewer than three channels are in
//! service there is none left to protect, and a latched dead end only keeps the vehicle without
//! rates or specific force after the cause is gone (every channel flagged invalid for a moment, a
//! connector that came back). So, and only then, the excluded channels are re-tested: the
//! candidates — channels in service plus excluded channels that are valid and off the converter
//! rails — must number at least three, every one of them must vary (a frozen converter does not
//! come back this way), and, when there are four or more, their parity test must raise no
//! alarm — the detector's own rule, the threshold exceeded k times in n — over
//! `readmit_after_samples` in a row. Then the excluded
//! candidates return together. With exactly three there is no parity to check them against each
//! other; they return on health alone, which is still better than no solution, and the parity test
//! resumes as soon as a fourth channel is back.
//!
//! The candidate set's parity space is built when the set changes (rare: it allocates), never per
//! sample.

use super::MAX_PARITY;
use super::parity::ParitySpace;
use super::persistence::Persistence;
use crate::geometry::{Geometry, MAX_CHANNELS};

/// The running re-test of one sensor type.
#[derive(Debug, Clone, Default)]
pub struct ExclusionRetest {
    /// Channels under test (bit i = channel i); 0 when no test runs.
    candidates: u32,
    /// Parity space of the candidates (four or more).
    space: Option<ParitySpace>,
    /// Consistent samples in a row.
    run: u32,
    /// Counts of the candidates on the first sample of the run.
    first_counts: [i16; MAX_CHANNELS],
    /// Candidates whose count differed from the first sample's during the run.
    varied: u32,
    /// The detector's k-of-n rule over the candidates' parity (`None` until the first sample).
    alarm: Option<Persistence>,
}

/// One sample of the re-test.
#[derive(Debug, Clone, Copy)]
pub struct RetestInput<'a> {
    /// Channels in service and excluded channels that are valid and off the rails.
    pub candidates: u32,
    /// Raw counts (channel i at index i).
    pub counts: &'a [i16],
    /// Calibrated values with the learnt channel offsets removed, SI.
    pub z: &'a [f64; MAX_CHANNELS],
}

impl ExclusionRetest {
    /// Forgets the run (the type has its solution, or the policy is off).
    pub fn clear(&mut self) {
        self.candidates = 0;
        self.space = None;
        self.run = 0;
        self.varied = 0;
        if let Some(alarm) = self.alarm.as_mut() {
            alarm.reset();
        }
    }

    /// Consistent samples in a row so far.
    pub fn run(&self) -> u32 {
        self.run
    }

    /// Pushes one sample; returns the candidates once they have been consistent for `needed`
    /// samples in a row (the run then restarts). `thresholds[m]`: the detection threshold for
    /// parity dimension m; `persistence`: the detector's (k, n) rule.
    pub fn push(
        &mut self,
        geometry: &Geometry,
        variances: &[f64; MAX_CHANNELS],
        thresholds: &[f64; MAX_PARITY + 1],
        persistence: (u32, u32),
        input: &RetestInput,
        needed: u32,
    ) -> Option<u32> {
        let n = geometry.n();
        if input.candidates != self.candidates {
            self.clear();
            self.candidates = input.candidates;
            if input.candidates.count_ones() >= 4 {
                self.space = ParitySpace::new(geometry, input.candidates, &variances[..n]).ok();
            }
        }
        let exceeded = !self.space_agrees(thresholds, input.z);
        let alarm = self
            .alarm
            .get_or_insert_with(|| Persistence::new(persistence.0, persistence.1));
        if self.candidates.count_ones() < 3 || alarm.push(exceeded) {
            self.run = 0;
            return None;
        }
        if self.run == 0 {
            self.varied = 0;
            for (i, first) in self.first_counts.iter_mut().enumerate().take(n) {
                *first = input.counts.get(i).copied().unwrap_or(0);
            }
        }
        for i in 0..n {
            if input
                .counts
                .get(i)
                .is_some_and(|&c| c != self.first_counts[i])
            {
                self.varied |= 1 << i;
            }
        }
        self.run = self.run.saturating_add(1);
        if self.run >= needed && self.varied & self.candidates == self.candidates {
            let back = self.candidates;
            self.run = 0;
            return Some(back);
        }
        None
    }

    /// The candidates' parity is below the threshold of its dimension on this sample (always true
    /// below four candidates, where there is none; false when their space could not be built).
    fn space_agrees(&self, thresholds: &[f64; MAX_PARITY + 1], z: &[f64; MAX_CHANNELS]) -> bool {
        if self.candidates.count_ones() < 4 {
            return true;
        }
        let Some(space) = &self.space else {
            return false;
        };
        if space.dimension() == 0 {
            return true;
        }
        let mut pw = [0.0; MAX_PARITY];
        let t = space.whitened_parity(z, &mut pw);
        t.is_finite() && t <= thresholds[space.dimension()]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::GeometryConfig;

    fn pyramid() -> Geometry {
        GeometryConfig::default().build().unwrap()
    }

    /// Channel values of body vector `x` on the pyramid, plus `noise[i]`.
    fn measure(g: &Geometry, x: [f64; 3], noise: [f64; 4]) -> [f64; MAX_CHANNELS] {
        let mut z = [0.0; MAX_CHANNELS];
        for (i, h) in g.axes().iter().enumerate() {
            z[i] = h[0] * x[0] + h[1] * x[1] + h[2] * x[2] + noise[i];
        }
        z
    }

    fn thresholds() -> [f64; MAX_PARITY + 1] {
        crate::fdi::FdiConfig::default()
            .settings()
            .unwrap()
            .thresholds
    }

    /// One sample of `candidates` with `counts` and values `z` on the pyramid, every channel at
    /// σ² = 1e-4, the detector's persistence (3 of 5) and 20 consistent samples needed.
    fn push(
        retest: &mut ExclusionRetest,
        g: &Geometry,
        candidates: u32,
        counts: &[i16],
        z: &[f64; MAX_CHANNELS],
    ) -> Option<u32> {
        let input = RetestInput {
            candidates,
            counts,
            z,
        };
        retest.push(g, &[1e-4; MAX_CHANNELS], &thresholds(), (3, 5), &input, 20)
    }

    #[test]
    fn consistent_varying_channels_return_after_the_run() {
        let g = pyramid();
        let mut retest = ExclusionRetest::default();
        let mut back = None;
        for k in 0..50 {
            let wiggle = 1e-3 * f64::from(k % 3);
            let z = measure(&g, [0.1, 0.0, 9.8], [wiggle, -wiggle, 0.0, wiggle]);
            let counts = [k as i16, -(k as i16), 7 + (k % 2) as i16, 3 * k as i16];
            back = push(&mut retest, &g, 0b1111, &counts, &z);
            if back.is_some() {
                assert_eq!(k, 19, "returned on the 20th consistent sample");
                break;
            }
        }
        assert_eq!(back, Some(0b1111));
    }

    #[test]
    fn an_inconsistent_channel_keeps_every_candidate_out() {
        let g = pyramid();
        let mut retest = ExclusionRetest::default();
        for k in 0..100 {
            // Channel 2 is 100 σ off: parity far above any threshold.
            let z = measure(&g, [0.1, 0.0, 9.8], [0.0, 0.0, 1.0, 0.0]);
            let counts = [k as i16; 4];
            assert_eq!(push(&mut retest, &g, 0b1111, &counts, &z), None);
            // The detector's rule: declared from the third exceedance on.
            assert!(retest.run() < 3, "run {} at sample {k}", retest.run());
        }
    }

    #[test]
    fn a_frozen_channel_does_not_come_back_and_fewer_than_three_never_do() {
        let g = pyramid();
        let mut retest = ExclusionRetest::default();
        for k in 0..100 {
            let z = measure(&g, [0.0, 0.0, 9.8], [0.0; 4]);
            // Channel 3 never changes its count.
            let counts = [k as i16, k as i16, k as i16, 5];
            assert_eq!(push(&mut retest, &g, 0b1111, &counts, &z), None);
        }
        assert!(
            retest.run() >= 20,
            "consistent, only the variation is missing"
        );
        let mut retest = ExclusionRetest::default();
        for k in 0..100 {
            let z = measure(&g, [0.0, 0.0, 9.8], [0.0; 4]);
            let counts = [k as i16; 4];
            assert_eq!(push(&mut retest, &g, 0b0011, &counts, &z), None);
        }
    }
}
