//! Small statistics helpers: sample mean and standard deviation over runs, RMS over a flight.

use serde::Serialize;

/// Mean and spread of one quantity over a set of samples (e.g. Monte Carlo runs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stat {
    /// Number of samples.
    pub n: usize,
    /// Sample mean (NaN when `n == 0`).
    pub mean: f64,
    /// Twice the sample standard deviation (n − 1 in the denominator; 0 when `n == 1`, NaN when
    /// `n == 0`).
    pub two_sigma: f64,
    /// Root mean square of the samples (NaN when `n == 0`).
    pub rms: f64,
    /// Smallest sample (NaN when `n == 0`).
    pub min: f64,
    /// Largest sample (NaN when `n == 0`).
    pub max: f64,
}

impl Stat {
    /// Statistics of `samples`. Non-finite samples propagate into every field but `n`.
    pub fn of(samples: &[f64]) -> Self {
        let n = samples.len();
        if n == 0 {
            return Self {
                n,
                mean: f64::NAN,
                two_sigma: f64::NAN,
                rms: f64::NAN,
                min: f64::NAN,
                max: f64::NAN,
            };
        }
        let count = n as f64;
        let mean = samples.iter().sum::<f64>() / count;
        // Two passes: the deviations from the mean are summed directly, which keeps the variance
        // accurate when the mean is large compared with the spread.
        let variance = if n > 1 {
            samples.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (count - 1.0)
        } else {
            0.0
        };
        let rms = (samples.iter().map(|x| x * x).sum::<f64>() / count).sqrt();
        let (min, max) = samples
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &x| {
                (lo.min(x), hi.max(x))
            });
        let propagate = |v: f64| {
            if samples.iter().all(|x| x.is_finite()) {
                v
            } else {
                f64::NAN
            }
        };
        Self {
            n,
            mean: propagate(mean),
            two_sigma: propagate(2.0 * variance.sqrt()),
            rms: propagate(rms),
            min: propagate(min),
            max: propagate(max),
        }
    }

    /// Standard deviation (half of `two_sigma`).
    pub fn sigma(&self) -> f64 {
        0.5 * self.two_sigma
    }
}

/// Running root mean square of a signal; allocation-free.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RmsAccumulator {
    sum_sq: f64,
    count: u64,
}

impl RmsAccumulator {
    /// An empty accumulator.
    pub const fn new() -> Self {
        Self {
            sum_sq: 0.0,
            count: 0,
        }
    }

    /// Adds one sample.
    pub fn push(&mut self, x: f64) {
        self.sum_sq += x * x;
        self.count += 1;
    }

    /// Adds the squared norm of a vector sample (`x` then is the vector's length).
    pub fn push_squared(&mut self, x_sq: f64) {
        self.sum_sq += x_sq;
        self.count += 1;
    }

    /// Samples added so far.
    pub fn count(&self) -> u64 {
        self.count
    }

    /// The RMS so far, `None` before the first sample.
    pub fn rms(&self) -> Option<f64> {
        (self.count > 0).then(|| (self.sum_sq / self.count as f64).sqrt())
    }
}

/// Root mean square of a slice (`None` when empty).
pub fn rms(samples: &[f64]) -> Option<f64> {
    let mut acc = RmsAccumulator::new();
    samples.iter().for_each(|&x| acc.push(x));
    acc.rms()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn stat_of_known_samples() {
        // 2, 4, 4, 4, 5, 5, 7, 9: mean 5, sum of squared deviations 32, sample variance 32/7.
        let s = Stat::of(&[2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]);
        assert_eq!(s.n, 8);
        assert!((s.mean - 5.0).abs() < 1e-15);
        assert!((s.two_sigma - 2.0 * (32.0_f64 / 7.0).sqrt()).abs() < 1e-14);
        assert!((s.rms - (232.0_f64 / 8.0).sqrt()).abs() < 1e-14);
        assert_eq!((s.min, s.max), (2.0, 9.0));
    }

    #[test]
    fn stat_of_one_and_none() {
        let one = Stat::of(&[3.0]);
        assert_eq!((one.mean, one.two_sigma, one.rms), (3.0, 0.0, 3.0));
        let none = Stat::of(&[]);
        assert_eq!(none.n, 0);
        assert!(none.mean.is_nan() && none.two_sigma.is_nan());
    }

    #[test]
    fn stat_propagates_nan() {
        let s = Stat::of(&[1.0, f64::NAN]);
        assert!(s.mean.is_nan() && s.two_sigma.is_nan() && s.max.is_nan());
    }

    #[test]
    fn large_offset_keeps_the_spread() {
        let s = Stat::of(&[1e9 + 1.0, 1e9 - 1.0]);
        // Deviations ±1: sample variance 2.
        assert!((s.sigma() - 2f64.sqrt()).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn gaussian_sample_sigma_within_its_standard_error() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let normal = Normal::new(1.5, 0.5).unwrap();
        let n = 20_000;
        let x: Vec<f64> = (0..n).map(|_| normal.sample(&mut rng)).collect();
        let s = Stat::of(&x);
        // Standard errors: σ/√n for the mean, σ/√(2(n−1)) for σ; allow 4 of them.
        assert!(
            (s.mean - 1.5).abs() < 4.0 * 0.5 / (n as f64).sqrt(),
            "{s:?}"
        );
        assert!(
            (s.sigma() - 0.5).abs() < 4.0 * 0.5 / (2.0 * (n as f64 - 1.0)).sqrt(),
            "{s:?}"
        );
    }

    #[test]
    fn rms_of_sine_is_amplitude_over_root_two() {
        let n = 10_000;
        let x: Vec<f64> = (0..n)
            .map(|k| 3.0 * (std::f64::consts::TAU * k as f64 / n as f64).sin())
            .collect();
        let r = rms(&x).unwrap();
        assert!((r - 3.0 / 2f64.sqrt()).abs() < 1e-12, "{r}");
        assert_eq!(rms(&[]), None);
    }

    proptest! {
        #[test]
        fn rms_bounds_mean_and_spread(x in proptest::collection::vec(-1e3f64..1e3, 2..50)) {
            let s = Stat::of(&x);
            let n = x.len() as f64;
            // rms² = mean² + (n−1)/n · σ² exactly.
            let lhs = s.rms * s.rms;
            let rhs = s.mean * s.mean + (n - 1.0) / n * s.sigma() * s.sigma();
            prop_assert!((lhs - rhs).abs() <= 1e-9 * (1.0 + lhs), "{lhs} {rhs}");
            prop_assert!(s.min <= s.mean && s.mean <= s.max);
        }
    }
}
