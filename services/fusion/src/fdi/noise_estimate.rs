//! Adaptive parity noise (`parity_noise = "adaptive"`): a slow estimate of the parity noise
//! covariance `S = E[p pᵀ]` for sensors that are noisier in service than their configuration
//! says (rotor vibration).
//!
//! - Seeded from the configured `V R Vᵀ`, which counts as [`SEED_WEIGHT`] samples.
//! - Learning phase (the first `learning_samples` samples, shared with [`super::offset`]): running
//!   mean of `p pᵀ` over every sample, no freezing, and the detector does not declare faults —
//!   with a seed far below the real noise, freezing above the threshold would lock the estimate
//!   and every sample would alarm.
//! - Afterwards: exponential average with gain 1/`window`, updated only while no sample of the
//!   persistence window exceeded the threshold (frozen while a fault may be present, so a fault
//!   is not learnt as noise). It averages the offset-corrected parity, so it is a covariance; a
//!   slow ramp that stays below the threshold is absorbed — the price of adapting.
//! - The whitening uses the estimate from the last refresh (every [`REFRESH_INTERVAL`] samples),
//!   so a sample costs m² multiply-adds and the Cholesky factor is rebuilt only occasionally.

use super::MAX_PARITY;
use super::dense::{ParityMatrix, cholesky, forward_substitute};

/// Weight of the configured covariance, in samples, when learning starts.
pub const SEED_WEIGHT: f64 = 10.0;
/// Samples between refreshes of the whitening from the estimate.
pub const REFRESH_INTERVAL: u32 = 64;

/// Running estimate of the parity noise covariance of one sensor type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdaptiveParityNoise {
    dim: usize,
    covariance: ParityMatrix,
    gain: f64,
    since_refresh: u32,
}

impl AdaptiveParityNoise {
    /// An estimator averaging over `window` samples once learning is over.
    pub fn new(window: u32) -> Self {
        Self {
            dim: 0,
            covariance: [[0.0; MAX_PARITY]; MAX_PARITY],
            gain: 1.0 / f64::from(window.max(1)),
            since_refresh: 0,
        }
    }

    /// Restarts the estimate in a (new) parity space of dimension `dim` from `configured`
    /// (V R Vᵀ) scaled by `inflation` (the noise excess learnt so far, 1 at start).
    pub fn seed(&mut self, configured: &ParityMatrix, dim: usize, inflation: f64) {
        self.dim = dim;
        for (row, cfg) in self.covariance.iter_mut().zip(configured) {
            for (s, c) in row.iter_mut().zip(cfg) {
                *s = c * inflation;
            }
        }
        self.since_refresh = 0;
    }

    /// Adds one offset-corrected, unwhitened parity vector `p`. Once learning is over, call only
    /// for samples below the threshold, and pass `truncation` = E[T | T < threshold]/m (see
    /// [`super::config::FdiSettings::truncation`]) so that skipping the tail does not shrink the
    /// estimate; while learning (every sample used) it is ignored. `learning_seen`: during the
    /// learning phase the number of samples already averaged, `None` afterwards. Returns true
    /// when the whitening should be refreshed from [`Self::covariance`].
    pub fn update(
        &mut self,
        p: &[f64; MAX_PARITY],
        learning_seen: Option<u64>,
        truncation: f64,
    ) -> bool {
        let (gain, scale) = match learning_seen {
            Some(seen) => (
                (1.0 / (seen as f64 + SEED_WEIGHT + 1.0)).max(self.gain),
                1.0,
            ),
            None => (self.gain, 1.0 / truncation),
        };
        for a in 0..self.dim {
            for b in 0..=a {
                let s =
                    self.covariance[a][b] + gain * (p[a] * p[b] * scale - self.covariance[a][b]);
                self.covariance[a][b] = s;
                self.covariance[b][a] = s;
            }
        }
        self.since_refresh += 1;
        if self.since_refresh >= REFRESH_INTERVAL {
            self.since_refresh = 0;
            true
        } else {
            false
        }
    }

    /// The current estimate of `E[p pᵀ]` (top-left m×m block).
    pub fn covariance(&self) -> &ParityMatrix {
        &self.covariance
    }

    /// Mean noise excess `tr(S_cfg⁻¹ S) / m` of the estimate over `configured`; 1 when there is no
    /// parity or `configured` is not positive definite.
    pub fn inflation_over(&self, configured: &ParityMatrix) -> f64 {
        let m = self.dim;
        let Some(l) = cholesky(configured, m).filter(|_| m > 0) else {
            return 1.0;
        };
        // tr(L⁻¹ S L⁻ᵀ): x[c] = L⁻¹ S[:, c] (column c of X = L⁻¹ S), then the diagonal of
        // L⁻¹ Xᵀ, whose column c is row c of X.
        let mut x = [[0.0; MAX_PARITY]; MAX_PARITY];
        for (c, xc) in x.iter_mut().enumerate().take(m) {
            *xc = std::array::from_fn(|r| self.covariance[r][c]);
            forward_substitute(&l, m, xc);
        }
        let trace: f64 = (0..m)
            .map(|c| {
                let mut row: [f64; MAX_PARITY] = std::array::from_fn(|r| x[r][c]);
                forward_substitute(&l, m, &mut row);
                row[c]
            })
            .sum();
        let ratio = trace / m as f64;
        if ratio.is_finite() && ratio > 0.0 {
            ratio
        } else {
            1.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn learns_a_scaled_covariance_and_reports_the_excess() {
        let mut cfg = [[0.0; MAX_PARITY]; MAX_PARITY];
        cfg[0][0] = 1.0;
        cfg[1][1] = 4.0;
        let mut est = AdaptiveParityNoise::new(100);
        est.seed(&cfg, 2, 1.0);
        assert!((est.inflation_over(&cfg) - 1.0).abs() < 1e-12);
        // Deterministic ±a, ±b sequence with E[p0²] = 9, E[p1²] = 36, E[p0 p1] = 0: 9× the config.
        let mut p = [0.0; MAX_PARITY];
        for t in 0..5000u64 {
            p[0] = if t % 2 == 0 { 3.0 } else { -3.0 };
            p[1] = if t % 4 < 2 { 6.0 } else { -6.0 };
            est.update(&p, (t < 1000).then_some(t), 1.0);
        }
        let s = est.covariance();
        assert!((s[0][0] - 9.0).abs() < 1e-6 && (s[1][1] - 36.0).abs() < 1e-6);
        assert!(s[0][1].abs() < 0.5);
        assert!((est.inflation_over(&cfg) - 9.0).abs() < 0.01);
    }
}
