//! The probation of a channel re-admitted by command: it is tested against the channels in service
//! while it stays out of the solution, and rejoins only once it passed.
//!
//! **Why out of the solution.** With four channels the parity space is one-dimensional: the parity
//! test detects a bias but cannot say which channel carries it, and only the stationary reference
//! isolates it, at rest. A biased channel put back into the solution would therefore raise a fault
//! that nobody can blame on it in flight — the bias goes into the fused rate and the attitude. Kept
//! out, the candidate is compared with the solution of the others, which names it by construction.
//!
//! **The tests**, each the one that can have excluded the channel:
//! - *missing*: the channel flagged invalid on any sample fails at once (reason `missing`);
//! - *stuck* and *noisy*: the channel-health checks of [`super::channel_health`] judge the
//!   candidate together with the channels in service (the same run length, the same comparison of
//!   its first-difference noise with its peers'); a verdict on it fails the probation at once with
//!   that reason; a channel at a converter rail where the others place the value well inside the
//!   range fails with `saturated`;
//! - *bias* (reason `parity`): its residual `r = z_c − h_cᵀ x̂`, x̂ the least-squares solution of
//!   the channels in service on the same sample. The true motion is in both terms and cancels; what
//!   is left is the candidate's bias plus the noise of the candidate and of the reference, of
//!   variance `σ_c² + h_cᵀ P h_c` (P the solution's covariance) plus the motion's share of the
//!   channel noise ([`super::FdiSettings::motion_noise_fraction`], `timing_skew_s`). Over the
//!   probation's N samples the mean of r has the standard deviation `s/√N`, s² the larger of that
//!   model variance and the residual's own sample variance (vibration above the configured noise
//!   must not make a healthy channel look biased). The candidate fails when
//!   `|mean| − a > k s/√N`, with `k²` the parity test's χ²(1) threshold (the per-sample exceedance
//!   probability behind the detector's false-alarm setting) and `a` the mean allowance for the
//!   disagreement the configuration declares in proportion to the motion (scale factor and
//!   misalignment between channels, `motion_noise_fraction` f): `f |x̂| √(1 + h_cᵀ P h_c / σ_c²)`
//!   per sample, since it does not average out in a steady turn (0 by default).
//!
//!   At the defaults k = 3.66: a false refusal in about 2.5e-4 probations; a bias of 5 s/√N is
//!   refused with probability 0.91, one of 6 s/√N with 0.99. With the default 1000 samples and
//!   the seed pyramid's gyros (s ≈ 2σ = 0.011 rad/s) k s/√N is 1.3e-3 rad/s (0.074 °/s), fifteen
//!   times below a 0.02 rad/s bias that parity detects but cannot isolate.
//!
//! The values the residual is taken on are the ones the solution uses (less the learnt channel
//! correction, [`super::monitor`]), so what the candidate would bring into the solution is judged:
//! a residual channel bias the correction has learnt does not count against it (nor does the share
//! of a fault the correction learnt while the fault was present but not yet declared — it is
//! subtracted from the channel either way). Samples at a converter rail are not accumulated (the
//! value is unknown there). Should the channels in service lose their solution during the
//! probation, it ends with the channel still excluded for its old reason: there is nothing to test
//! it against, and the recovery re-test ([`super::recovery`]) takes it up with the others.
//!
//! Fixed arrays, no allocation: per sample and channel on probation, a few products and sums.

use crate::geometry::MAX_CHANNELS;
use ipc_types::FaultReason;

/// Where the probation of one channel stands after a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProbationVerdict {
    /// Still under test.
    Testing,
    /// Passed every test over the whole probation: the channel rejoins the solution.
    Passed,
    /// Failed the test of this reason: the channel stays excluded, now for it.
    Failed(FaultReason),
}

/// The bias test's running sums for the channels on probation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ProbationTest {
    /// Samples of residual needed for a verdict.
    samples: u32,
    /// Bound on |mean| in standard deviations of the mean.
    k: f64,
    /// Channels on probation (bit i = channel i).
    channels: u32,
    count: [u32; MAX_CHANNELS],
    /// Running mean of the residual (Welford).
    mean: [f64; MAX_CHANNELS],
    /// Running sum of squared deviations from the mean (Welford).
    m2: [f64; MAX_CHANNELS],
    /// Sum of the model variances of the residual.
    model: [f64; MAX_CHANNELS],
    /// Sum of the allowances for the declared systematic disagreement.
    allowance: [f64; MAX_CHANNELS],
}

impl ProbationTest {
    /// A probation of `samples` residuals per channel (at least 2), the mean bounded by
    /// `√chi2_threshold` standard deviations of the mean (`chi2_threshold`: the parity test's
    /// one-dimensional threshold).
    pub fn new(samples: u32, chi2_threshold: f64) -> Self {
        Self {
            samples: samples.max(2),
            k: chi2_threshold.max(0.0).sqrt(),
            channels: 0,
            count: [0; MAX_CHANNELS],
            mean: [0.0; MAX_CHANNELS],
            m2: [0.0; MAX_CHANNELS],
            model: [0.0; MAX_CHANNELS],
            allowance: [0.0; MAX_CHANNELS],
        }
    }

    /// Puts `channel` on probation (again from the start when it already was).
    pub fn start(&mut self, channel: usize) {
        if channel < MAX_CHANNELS {
            self.channels |= 1 << channel;
            self.count[channel] = 0;
            self.mean[channel] = 0.0;
            self.m2[channel] = 0.0;
            self.model[channel] = 0.0;
            self.allowance[channel] = 0.0;
        }
    }

    /// Ends the probation of `channel` without a verdict of this test.
    pub fn stop(&mut self, channel: usize) {
        if channel < MAX_CHANNELS {
            self.channels &= !(1 << channel);
        }
    }

    /// Channels on probation (bit i = channel i).
    pub fn channels(&self) -> u32 {
        self.channels
    }

    /// Samples of residual `channel` has had.
    pub fn count(&self, channel: usize) -> u32 {
        self.count.get(channel).copied().unwrap_or(0)
    }

    /// Adds one residual `r` of `channel` with its model variance `variance` and the systematic
    /// disagreement `allowance` the configuration declares for this sample (SI, ≥ 0: it does not
    /// average out, so it widens the bound on the mean rather than the variance); after the last
    /// sample of the probation, the bias verdict (the probation of the channel then ends).
    pub fn push(
        &mut self,
        channel: usize,
        r: f64,
        variance: f64,
        allowance: f64,
    ) -> ProbationVerdict {
        if channel >= MAX_CHANNELS || self.channels & (1 << channel) == 0 {
            return ProbationVerdict::Testing;
        }
        if !(r.is_finite() && variance.is_finite()) {
            // A value that cannot be judged is not evidence of health.
            self.stop(channel);
            return ProbationVerdict::Failed(FaultReason::Parity);
        }
        let n = self.count[channel] + 1;
        self.count[channel] = n;
        let d = r - self.mean[channel];
        self.mean[channel] += d / f64::from(n);
        self.m2[channel] += d * (r - self.mean[channel]);
        self.model[channel] += variance;
        self.allowance[channel] += allowance.max(0.0);
        if n < self.samples {
            return ProbationVerdict::Testing;
        }
        self.stop(channel);
        if self.bias_score(channel) > self.k {
            ProbationVerdict::Failed(FaultReason::Parity)
        } else {
            ProbationVerdict::Passed
        }
    }

    /// |mean residual| of `channel`, less the mean allowance, in standard deviations of the mean
    /// so far (0 before two samples): what the bias test compares with its bound.
    pub fn bias_score(&self, channel: usize) -> f64 {
        let Some(&n) = self.count.get(channel).filter(|&&n| n >= 2) else {
            return 0.0;
        };
        let n = f64::from(n);
        let sample = self.m2[channel] / (n - 1.0);
        let model = self.model[channel] / n;
        let s2 = sample.max(model);
        let excess = (self.mean[channel].abs() - self.allowance[channel] / n).max(0.0);
        if s2 > 0.0 {
            excess / (s2 / n).sqrt()
        } else if excess == 0.0 {
            0.0
        } else {
            f64::INFINITY
        }
    }

    /// The bound on [`Self::bias_score`].
    pub fn bound(&self) -> f64 {
        self.k
    }

    /// Mean residual of `channel` so far, SI.
    pub fn mean(&self, channel: usize) -> f64 {
        self.mean.get(channel).copied().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// Bias verdict after `n` residuals of σ `sigma` around `bias`, model variance σ².
    fn verdict(
        bias: f64,
        sigma: f64,
        model_sigma: f64,
        n: u32,
        seed: u64,
    ) -> (ProbationVerdict, f64) {
        let mut t = ProbationTest::new(n, 3.66f64.powi(2));
        t.start(1);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut last = ProbationVerdict::Testing;
        let mut score = 0.0;
        for k in 0..n {
            let e: f64 = StandardNormal.sample(&mut rng);
            score = t.bias_score(1);
            last = t.push(1, bias + sigma * e, model_sigma * model_sigma, 0.0);
            if k + 1 < n {
                assert_eq!(last, ProbationVerdict::Testing);
            }
        }
        assert_eq!(t.channels(), 0, "the verdict ends the probation");
        (last, score)
    }

    #[test]
    fn a_bias_of_several_deviations_of_the_mean_fails_and_none_passes() {
        let n = 1000;
        let sd_mean = 1.0 / f64::from(n).sqrt();
        // 8 deviations of the mean: |N(8, 1)| > 3.66 except with probability 1e-5.
        for seed in 0..20 {
            assert_eq!(
                verdict(8.0 * sd_mean, 1.0, 1.0, n, seed).0,
                ProbationVerdict::Failed(FaultReason::Parity),
                "seed {seed}"
            );
            assert_eq!(
                verdict(0.0, 1.0, 1.0, n, seed).0,
                ProbationVerdict::Passed,
                "seed {seed}"
            );
        }
    }

    #[test]
    fn the_larger_of_the_model_and_the_sample_variance_sets_the_bound() {
        let n = 1000;
        // The residual is 3× noisier than the model says: a bias of 8 model deviations of the
        // mean is under 3 actual ones and passes; judged by the model alone it would fail.
        let sd_mean = 1.0 / f64::from(n).sqrt();
        let (v, score) = verdict(8.0 * sd_mean, 3.0, 1.0, n, 3);
        assert_eq!(v, ProbationVerdict::Passed, "score {score}");
        // A model larger than the sample variance is used as it is.
        let (v, _) = verdict(8.0 * sd_mean, 1.0, 3.0, n, 3);
        assert_eq!(v, ProbationVerdict::Passed);
    }

    #[test]
    fn the_allowance_comes_off_the_mean_before_it_is_judged() {
        let mut t = ProbationTest::new(4, 9.0);
        t.start(0);
        // Mean 1.0, sample variance 0, model variance 0.04 → sd of the mean 0.1.
        for _ in 0..3 {
            assert_eq!(t.push(0, 1.0, 0.04, 0.75), ProbationVerdict::Testing);
        }
        assert_eq!(t.push(0, 1.0, 0.04, 0.75), ProbationVerdict::Passed);
        assert!((t.bias_score(0) - 2.5).abs() < 1e-12);
        t.start(0);
        for _ in 0..3 {
            t.push(0, 1.0, 0.04, 0.65);
        }
        assert_eq!(
            t.push(0, 1.0, 0.04, 0.65),
            ProbationVerdict::Failed(FaultReason::Parity)
        );
        assert!((t.bias_score(0) - 3.5).abs() < 1e-12);
    }

    #[test]
    fn the_default_bound_is_the_one_the_docs_give() {
        let settings = crate::fdi::FdiConfig::default().settings().unwrap();
        let k = ProbationTest::new(1000, settings.thresholds[1]).bound();
        assert!((k - 3.66).abs() < 0.005, "{k}");
    }

    #[test]
    fn a_value_that_cannot_be_judged_fails_and_unknown_channels_are_ignored() {
        let mut t = ProbationTest::new(10, 13.8);
        t.start(0);
        assert_eq!(t.push(3, 1.0, 1.0, 0.0), ProbationVerdict::Testing);
        assert_eq!(t.push(99, 1.0, 1.0, 0.0), ProbationVerdict::Testing);
        assert_eq!(
            t.push(0, f64::NAN, 1.0, 0.0),
            ProbationVerdict::Failed(FaultReason::Parity)
        );
        assert_eq!(t.channels(), 0);
    }
}
