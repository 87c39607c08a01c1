//! k-of-n persistence: a fault is declared when the test statistic exceeded its threshold in at
//! least k of the last n samples.
//!
//! **False-alarm arithmetic.** With fault-free samples exceeding independently with probability
//! α₁, a *new* declaration at sample t (the count of the window ending at t reaches k while the
//! window ending at t − 1 held k − 1) needs: an exceedance at t, exactly k − 1 among the n − 1
//! samples before it, and none at t − n, which leaves the window. So the declared false-alarm
//! probability per sample is exactly
//!
//! ```text
//! α = C(n−1, k−1) · α₁^k · (1 − α₁)^(n−k+1)
//! ```
//!
//! [`exceedance_probability`] inverts this: the configured `false_alarm_probability` is α, the
//! probability that a fault-free sample raises an alarm, and the per-sample χ² threshold is taken
//! at α₁. With the defaults (α = 1e-7, k = 3, n = 5): α₁ = 2.561e-3, i.e. a χ²(1) threshold of
//! 9.10 (3.02 σ of the parity noise). A 5 σ bias step exceeds it with probability 0.976 per
//! sample, so it is declared on its 3rd sample with probability 0.93 and within 10 samples with
//! probability 1 − 8e-9. At 1 kHz, α = 1e-7 means 3.6e6 · 1e-7 = **0.36 expected false alarms per
//! hour** per sensor type; α = 1e-10 gives 3.6e-4 per hour (α₁ = 2.56e-4, threshold 13.37 =
//! 3.66 σ; a 5 σ step is then declared within 10 samples with probability 1 − 2e-5).

/// Longest persistence window (the history is a bit field).
pub const MAX_PERSISTENCE_WINDOW: usize = 16;

/// Binomial coefficient C(n, k) as a float.
fn binomial(n: u32, k: u32) -> f64 {
    (0..k).fold(1.0, |acc, j| acc * f64::from(n - j) / f64::from(j + 1))
}

/// Declared false-alarm probability per sample for a per-sample exceedance probability `alpha1`
/// (the formula in the module documentation).
pub fn declared_false_alarm_probability(alpha1: f64, k: u32, n: u32) -> f64 {
    binomial(n - 1, k - 1) * alpha1.powi(k as i32) * (1.0 - alpha1).powi((n - k + 1) as i32)
}

/// The per-sample exceedance probability α₁ whose k-of-n declarations occur with probability
/// `declared` per fault-free sample; `None` when `declared` is above what any α₁ can give (the
/// maximum of the formula, at α₁ = k/(n+1)) or k, n are out of range (1 ≤ k ≤ n ≤ 16).
pub fn exceedance_probability(declared: f64, k: u32, n: u32) -> Option<f64> {
    if !(1..=n).contains(&k) || n as usize > MAX_PERSISTENCE_WINDOW {
        return None;
    }
    if !(declared > 0.0 && declared.is_finite()) {
        return None;
    }
    let peak = f64::from(k) / f64::from(n + 1);
    if declared > declared_false_alarm_probability(peak, k, n) {
        return None;
    }
    // Monotone increasing on [0, peak]: bisection in log space for tiny probabilities.
    let (mut lo, mut hi) = (0.0_f64, peak);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if declared_false_alarm_probability(mid, k, n) < declared {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-15 * hi {
            break;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Sliding k-of-n counter over the per-sample exceedances.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Persistence {
    k: u32,
    n: u32,
    /// Bit j = exceedance j samples ago.
    history: u32,
}

impl Persistence {
    /// A counter declaring on `k` exceedances within `n` samples (1 ≤ k ≤ n ≤ 16, checked by the
    /// configuration; out-of-range values are clamped).
    pub fn new(k: u32, n: u32) -> Self {
        let n = n.clamp(1, MAX_PERSISTENCE_WINDOW as u32);
        Self {
            k: k.clamp(1, n),
            n,
            history: 0,
        }
    }

    /// Records one sample; true while at least k of the last n samples exceeded.
    pub fn push(&mut self, exceeded: bool) -> bool {
        let window = (1u32 << self.n) - 1;
        self.history = ((self.history << 1) | u32::from(exceeded)) & window;
        self.history.count_ones() >= self.k
    }

    /// True while at least k of the last n samples exceeded.
    pub fn declared(&self) -> bool {
        self.history.count_ones() >= self.k
    }

    /// Exceedances in the current window.
    pub fn count(&self) -> u32 {
        self.history.count_ones()
    }

    /// Forgets the history (after a change of the active channel set).
    pub fn reset(&mut self) {
        self.history = 0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_k_of_the_last_n() {
        let mut p = Persistence::new(3, 5);
        let pattern = [
            true, false, true, false, false, true, false, false, false, true,
        ];
        let declared: Vec<bool> = pattern.iter().map(|&e| p.push(e)).collect();
        // Exceedances at 0, 2, 5 and 9: no window of five samples holds three of them.
        assert!(declared.iter().all(|d| !d));
        let mut p = Persistence::new(3, 5);
        assert_eq!(
            [true, false, true, true, false, false, false].map(|e| p.push(e)),
            [false, false, false, true, true, false, false]
        );
        p.reset();
        assert_eq!(p.count(), 0);
    }

    #[test]
    fn exceedance_probability_inverts_the_declared_rate() {
        for (k, n) in [(3, 5), (1, 1), (2, 2), (4, 10), (16, 16)] {
            for declared in [1e-12, 1e-7, 1e-3] {
                let a1 = exceedance_probability(declared, k, n).unwrap();
                let back = declared_false_alarm_probability(a1, k, n);
                assert!(
                    (back / declared - 1.0).abs() < 1e-9,
                    "k {k} n {n}: {back} vs {declared}"
                );
            }
        }
        // Defaults: 6 α₁³ (1 − α₁)³ = 1e-7.
        let a1 = exceedance_probability(1e-7, 3, 5).unwrap();
        assert!((a1 - 2.5609e-3).abs() < 1e-7, "{a1}");
        assert!(exceedance_probability(0.5, 3, 5).is_none());
        assert!(exceedance_probability(1e-7, 6, 5).is_none());
        assert!(exceedance_probability(1e-7, 3, 17).is_none());
    }
}
