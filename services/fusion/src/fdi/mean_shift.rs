//! The mean-shift test: a fault too small for the per-sample parity test.
//!
//! The per-sample test with its k-of-n persistence declares a bias only once single samples
//! exceed the threshold often enough. A bias of two channel σ on one of four skewed gyros moves
//! the whitened parity by about one unit: a single sample exceeds the threshold a few percent of
//! the time, and the declaration took seconds while the attitude integrated the error. Averaged
//! over W samples, the same bias stands √W times above the noise.
//!
//! The test keeps an exponentially weighted mean `m` of the whitened parity (weight α = 2/(W+1),
//! the same noise reduction as a W-sample mean). Fault-free, each component of `m` has variance
//! α/(2−α), so `T = |m|²·(2−α)/α` is χ²(dim); it alarms above the χ² quantile of the configured
//! false-alarm probability p. The mean moves by about √(2α) of its σ per sample, so it crosses a
//! level u σ (one dimension: p = P(|Z| > u)) about `p·u·√(α/π)` times per sample (Rice's
//! argument for a sampled process), i.e. `p·W·u·√(α/π)` times per window: 37 p at p = 1e-3 and
//! 73 p at the default 1e-10 (u = 6.5) with W = 200, which at 1 kHz is 1.3e-4 alarms per hour
//! per sensor type, below the per-sample test's 3.6e-4. A step of b whitened units reaches the
//! threshold x after about `−ln(1 − √(x·α/(2−α))/b)/α` samples: 61 for b = 1, W = 200.
//!
//! No allocation: the mean is a fixed array.

use super::MAX_PARITY;

/// Exponentially weighted mean of the whitened parity and its χ² test.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeanShift {
    /// Weight of the newest sample; 0: the test is off.
    alpha: f64,
    /// The scale `(2 − α)/α` that makes `|m|²` a χ² statistic.
    scale: f64,
    mean: [f64; MAX_PARITY],
}

impl MeanShift {
    /// A test averaging over about `window` samples (0: off).
    pub fn new(window: u32) -> Self {
        let alpha = if window == 0 {
            0.0
        } else {
            2.0 / (f64::from(window) + 1.0)
        };
        Self {
            alpha,
            scale: if alpha > 0.0 {
                (2.0 - alpha) / alpha
            } else {
                0.0
            },
            mean: [0.0; MAX_PARITY],
        }
    }

    /// Whether the test runs.
    pub fn enabled(&self) -> bool {
        self.alpha > 0.0
    }

    /// Adds one whitened parity vector (`dim` entries) and returns the test statistic, χ²(dim)
    /// when fault-free (0 when off).
    pub fn push(&mut self, pw: &[f64; MAX_PARITY], dim: usize) -> f64 {
        if !self.enabled() {
            return 0.0;
        }
        let a = self.alpha;
        let mut t = 0.0;
        for (m, p) in self.mean.iter_mut().zip(pw).take(dim) {
            // A non-finite parity (a channel without a value) must not poison the mean for ever.
            if p.is_finite() {
                *m += a * (p - *m);
            }
            t += *m * *m;
        }
        t * self.scale
    }

    /// The mean so far, in whitened units (the first `dim` entries are meaningful).
    pub fn mean(&self) -> &[f64; MAX_PARITY] {
        &self.mean
    }

    /// How many samples' worth of evidence the mean holds: the length whose plain mean has the
    /// same noise, `(2 − α)/α`.
    pub fn effective_len(&self) -> f64 {
        self.scale
    }

    /// Forgets the mean (the active set, and with it the parity space, changed).
    pub fn clear(&mut self) {
        self.mean = [0.0; MAX_PARITY];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    #[test]
    fn fault_free_the_statistic_is_chi2_and_a_one_sigma_step_is_found_within_a_hundred_samples() {
        let mut test = MeanShift::new(200);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let (mut sum, mut n) = (0.0, 0);
        let mut pw = [0.0; MAX_PARITY];
        for k in 0..200_000 {
            pw[0] = StandardNormal.sample(&mut rng);
            let t = test.push(&pw, 1);
            if k > 2000 {
                sum += t;
                n += 1;
            }
        }
        // E[χ²(1)] = 1; successive values are strongly correlated, hence the loose bound.
        let mean = sum / f64::from(n);
        assert!((mean - 1.0).abs() < 0.1, "{mean}");

        // χ²(1) quantile at 1e-10 ≈ 41.8: a step of one whitened unit needs about 61 samples.
        let threshold = 41.8;
        let mut test = MeanShift::new(200);
        pw[0] = 1.0;
        let at = (1..1000)
            .find(|_| test.push(&pw, 1) > threshold)
            .expect("declared");
        assert!((55..=70).contains(&at), "{at}");
        assert!((test.effective_len() - 200.0).abs() < 1.0);
    }

    /// At a configured probability of 1e-3 the alarm's rising edges come at the rate the module
    /// docs derive: `p·u·√(α/π)` per sample.
    #[test]
    fn the_alarm_rate_follows_the_crossing_argument() {
        // χ²(1) upper quantile at 1e-3.
        let threshold = 10.828;
        let window = 200;
        let mut test = MeanShift::new(window);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut pw = [0.0; MAX_PARITY];
        let (mut edges, mut previous) = (0u32, false);
        const SAMPLES: u32 = 2_000_000;
        for _ in 0..SAMPLES {
            pw[0] = StandardNormal.sample(&mut rng);
            let alarm = test.push(&pw, 1) > threshold;
            edges += u32::from(alarm && !previous);
            previous = alarm;
        }
        let alpha = 2.0 / (f64::from(window) + 1.0);
        let expected =
            1e-3 * threshold.sqrt() * (alpha / std::f64::consts::PI).sqrt() * f64::from(SAMPLES);
        // About 370 edges: within 25 % (the argument's approximations, and 5 Poisson σ).
        let ratio = f64::from(edges) / expected;
        assert!(
            (0.75..1.25).contains(&ratio),
            "{edges} edges, {expected} expected"
        );
    }

    #[test]
    fn off_and_non_finite_input() {
        let mut off = MeanShift::new(0);
        assert!(!off.enabled());
        assert_eq!(off.push(&[5.0; MAX_PARITY], 3), 0.0);
        let mut test = MeanShift::new(10);
        let mut pw = [0.0; MAX_PARITY];
        pw[0] = f64::NAN;
        assert_eq!(test.push(&pw, 1), 0.0);
        pw[0] = 1.0;
        assert!(test.push(&pw, 1).is_finite());
        test.clear();
        assert_eq!(test.mean()[0], 0.0);
    }
}
