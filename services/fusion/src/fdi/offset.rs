//! Parity offset: a slow estimate of the mean of the parity vector, subtracted before the test.
//!
//! Channel biases that calibration left behind (turn-on bias: a few mg on MEMS accelerometers,
//! about one channel σ) do not cancel in the parity vector: p = V(Hx + β + ε) = Vβ + Vε. A
//! constant offset of 1 σ of the parity noise multiplies the per-sample exceedance probability
//! by about ten and the k-of-n false-alarm rate by about a thousand — a false alarm every few
//! seconds at 1 kHz. The parity-visible part of the biases, Vβ, is exactly the mean of p, so it is
//! learnt the way the gyro bias is learnt at rest before a walk (\[R3\]):
//!
//! - learning phase (the first `learning_samples` samples): running mean of p, no parity
//!   declarations (the channel-health checks stay active);
//! - afterwards: exponential average with gain 1/`window`, updated only while no sample of the
//!   persistence window exceeded the threshold (a fault must not become "offset").
//!
//! A bias *step* is detected at once (the estimate moves by 1/`window` of it per sample). A bias
//! *ramp* of r per second is seen with a lag of at most r·τ (τ = `window` samples at the sample
//! rate), so ramps faster than threshold/τ (≈ 3 σ per minute at the default τ = 60 s) are still
//! detected; slower drifts are absorbed — they are indistinguishable from bias instability.
//!
//! When the active set changes, the offset is carried over exactly: with P = VᵀV the parity
//! projector, V'β = V'(Pβ) = V'Vᵀb for the new basis V' (the rest of β lies in the column space of
//! H, which V' annihilates), see [`super::parity::ParitySpace::carry_over`].

use super::MAX_PARITY;

/// Running mean of the parity vector of one sensor type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParityOffset {
    mean: [f64; MAX_PARITY],
    gain: f64,
}

impl ParityOffset {
    /// An estimate averaging over `window` samples once learning is over (≥ 1).
    pub fn new(window: u32) -> Self {
        Self {
            mean: [0.0; MAX_PARITY],
            gain: 1.0 / f64::from(window.max(1)),
        }
    }

    /// Adds the raw parity vector `p` (first `dim` entries). `learning_seen`: during the learning
    /// phase the number of samples already averaged (running mean), `None` afterwards.
    pub fn update(&mut self, p: &[f64; MAX_PARITY], dim: usize, learning_seen: Option<u64>) {
        let gain = match learning_seen {
            Some(seen) => (1.0 / (seen as f64 + 1.0)).max(self.gain),
            None => self.gain,
        };
        for (m, v) in self.mean.iter_mut().zip(p).take(dim) {
            *m += gain * (v - *m);
        }
    }

    /// The current estimate.
    pub fn mean(&self) -> &[f64; MAX_PARITY] {
        &self.mean
    }

    /// Replaces the estimate (after a reconfiguration).
    pub fn set_mean(&mut self, mean: [f64; MAX_PARITY]) {
        self.mean = mean;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn learns_the_running_mean_then_follows_slowly() {
        let mut o = ParityOffset::new(1000);
        let mut p = [0.0; MAX_PARITY];
        for k in 0..100u64 {
            p[0] = if k % 2 == 0 { 3.0 } else { 1.0 };
            o.update(&p, 1, Some(k));
        }
        assert!(
            (o.mean()[0] - 2.0).abs() < 1e-12,
            "running mean of 3, 1, 3, 1, …"
        );
        // After learning: a step of 10 moves the estimate by 1/1000 of it per sample.
        p[0] = 12.0;
        o.update(&p, 1, None);
        assert!((o.mean()[0] - 2.01).abs() < 1e-12);
    }
}
