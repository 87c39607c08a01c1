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
//! H, which V' annihilates), see [`ParityOffset::carry_over`]. It goes through channel terms, so
//! it also outlives a spell without a parity space (fewer than four channels).
//!
//! **Motion** (`motion_offset`). Channels whose scale factors or axes differ from the geometry by
//! a small relative error E (channel i reads `(h_i + e_i)·x + β_i`) give a parity that grows with
//! the motion: p = V(E x + β) + Vε. A single-IMU filter cannot see E; the redundancy can, in the
//! parity space, which is exactly the part that reaches the test. With the option on, the offset
//! is a regression of p on φ = [1, x] (x the fused value of this sample, before the test) instead
//! of a mean: p ≈ a + B x, one 4 × 4 system shared by every parity component, learnt with the
//! same gains and gating as the mean, the slopes B held towards zero by a prior of
//! [`SLOPE_PRIOR_SIGMA`] per fused unit until the motion determines them. The parity of the
//! common part of E (every channel turned alike: the mounting of the whole block) is zero, so it
//! is neither seen nor removed: the fused value is not changed, only the test no longer reads the
//! channels' relative misalignment during a manoeuvre as a fault. Allocation-free; one 4 × 4
//! Cholesky factorisation per sample.

use nalgebra::{Matrix4, Vector4};

use super::MAX_PARITY;
use super::parity::ParitySpace;
use crate::geometry::MAX_CHANNELS;

/// Prior σ of each slope of the motion regression, parity per unit of the fused value: relative
/// scale factor and misalignment errors of a few per cent (3° of misalignment is 0.05).
pub const SLOPE_PRIOR_SIGMA: f64 = 0.05;

/// Running mean of the parity vector of one sensor type, or with motion its regression on the
/// fused value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParityOffset {
    /// The offset at a zero fused value (the mean without motion), per parity component.
    mean: [f64; MAX_PARITY],
    /// Growth of each parity component with the fused value (zero without motion).
    slopes: [[f64; 3]; MAX_PARITY],
    motion: Option<MotionMoments>,
    gain: f64,
    /// The offset and slopes in channel terms, as of the last parity space that had them.
    channel_mean: [f64; MAX_CHANNELS],
    channel_slopes: [[f64; MAX_CHANNELS]; 3],
}

/// Weighted means of the regression's normal equations.
#[derive(Debug, Clone, Copy, PartialEq)]
struct MotionMoments {
    /// Mean of φφᵀ, φ = [1, x].
    phi: Matrix4<f64>,
    /// Mean of p_k φ, per parity component.
    cross: [Vector4<f64>; MAX_PARITY],
    /// The prior's weight on the slopes at the last update.
    ridge: f64,
}

impl ParityOffset {
    /// An estimate averaging over `window` samples once learning is over (≥ 1).
    pub fn new(window: u32) -> Self {
        Self {
            mean: [0.0; MAX_PARITY],
            slopes: [[0.0; 3]; MAX_PARITY],
            motion: None,
            gain: 1.0 / f64::from(window.max(1)),
            channel_mean: [0.0; MAX_CHANNELS],
            channel_slopes: [[0.0; MAX_CHANNELS]; 3],
        }
    }

    /// The same, regressing the parity on the fused value (see the module docs).
    pub fn with_motion(window: u32) -> Self {
        Self {
            motion: Some(MotionMoments {
                phi: Matrix4::zeros(),
                cross: [Vector4::zeros(); MAX_PARITY],
                ridge: 0.0,
            }),
            ..Self::new(window)
        }
    }

    /// Adds the raw parity vector `p` (first `dim` entries) seen at fused value `x`.
    /// `learning_seen`: during the learning phase the number of samples already averaged (running
    /// mean), `None` afterwards. `noise_variance`: the parity noise per component, which sets how
    /// much data the slopes need before they leave their prior.
    pub fn update(
        &mut self,
        p: &[f64; MAX_PARITY],
        x: &[f64; 3],
        dim: usize,
        learning_seen: Option<u64>,
        noise_variance: f64,
    ) {
        let gain = match learning_seen {
            Some(seen) => (1.0 / (seen as f64 + 1.0)).max(self.gain),
            None => self.gain,
        };
        let Some(m) = self.motion.as_mut() else {
            for (mean, v) in self.mean.iter_mut().zip(p).take(dim) {
                *mean += gain * (v - *mean);
            }
            return;
        };
        let phi = Vector4::new(1.0, x[0], x[1], x[2]);
        m.phi += gain * (phi * phi.transpose() - m.phi);
        for (c, v) in m.cross.iter_mut().zip(p).take(dim) {
            *c += gain * (*v * phi - *c);
        }
        // In mean form the prior's information per sample is the noise over (samples × σ²).
        let samples = 1.0 / gain;
        m.ridge = (noise_variance / (samples * SLOPE_PRIOR_SIGMA * SLOPE_PRIOR_SIGMA))
            .max(1e-12 * m.phi.trace());
        self.solve(dim);
    }

    /// Recomputes the coefficients from the moments.
    fn solve(&mut self, dim: usize) {
        let Some(m) = &self.motion else { return };
        let mut a = m.phi;
        for k in 1..4 {
            a[(k, k)] += m.ridge;
        }
        let Some(chol) = a.cholesky() else { return };
        for k in 0..dim {
            let c = chol.solve(&m.cross[k]);
            self.mean[k] = c[0];
            self.slopes[k] = [c[1], c[2], c[3]];
        }
    }

    /// The offset at fused value `x`, per parity component (first `dim` entries).
    pub fn at(&self, x: &[f64; 3], dim: usize) -> [f64; MAX_PARITY] {
        let mut out = self.mean;
        for (o, b) in out.iter_mut().zip(&self.slopes).take(dim) {
            *o += b[0] * x[0] + b[1] * x[1] + b[2] * x[2];
        }
        out
    }

    /// The current offset at a zero fused value (the mean without motion).
    pub fn mean(&self) -> &[f64; MAX_PARITY] {
        &self.mean
    }

    /// The offset in channel terms, as of the last change of the active set (zero before one).
    pub fn channel_mean(&self) -> &[f64; MAX_CHANNELS] {
        &self.channel_mean
    }

    /// The current slopes, per parity component (zero without motion).
    pub fn slopes(&self) -> &[[f64; 3]; MAX_PARITY] {
        &self.slopes
    }

    /// Replaces the offset at a zero fused value (after a bias removed upstream), keeping the
    /// slopes; the moments follow, so the next sample continues from it.
    pub fn set_mean(&mut self, mean: [f64; MAX_PARITY]) {
        self.mean = mean;
        self.sync_moments();
    }

    /// Makes the moments give the current coefficients (after they were set from outside).
    fn sync_moments(&mut self) {
        let (mean, slopes) = (self.mean, self.slopes);
        let Some(m) = self.motion.as_mut() else {
            return;
        };
        let mut a = m.phi;
        for k in 1..4 {
            a[(k, k)] += m.ridge;
        }
        for ((c, mu), b) in m.cross.iter_mut().zip(mean).zip(slopes) {
            *c = a * Vector4::new(mu, b[0], b[1], b[2]);
        }
    }

    /// Carries the offset from the parity space `old` to `new` after the active set changed,
    /// through channel terms (kept while there is no parity space).
    pub fn carry_over(&mut self, old: Option<&ParitySpace>, new: Option<&ParitySpace>) {
        if let Some(old) = old {
            self.channel_mean = old.to_channels(&self.mean);
            for (axis, channels) in self.channel_slopes.iter_mut().enumerate() {
                let column = std::array::from_fn(|k| self.slopes[k][axis]);
                *channels = old.to_channels(&column);
            }
        }
        let mut mean = [0.0; MAX_PARITY];
        let mut slopes = [[0.0; 3]; MAX_PARITY];
        if let Some(new) = new {
            new.parity(&self.channel_mean, &mut mean);
            for (axis, channels) in self.channel_slopes.iter().enumerate() {
                let mut column = [0.0; MAX_PARITY];
                new.parity(channels, &mut column);
                for (b, c) in slopes.iter_mut().zip(column) {
                    b[axis] = c;
                }
            }
        }
        self.mean = mean;
        self.slopes = slopes;
        self.sync_moments();
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
            o.update(&p, &[0.0; 3], 1, Some(k), 1.0);
        }
        assert!(
            (o.mean()[0] - 2.0).abs() < 1e-12,
            "running mean of 3, 1, 3, 1, …"
        );
        // After learning: a step of 10 moves the estimate by 1/1000 of it per sample.
        p[0] = 12.0;
        o.update(&p, &[0.0; 3], 1, None, 1.0);
        assert!((o.mean()[0] - 2.01).abs() < 1e-12);
    }

    /// Parity noise σ 0.01 on two components; the channels' relative errors give component 0 a
    /// constant 0.03 and slopes (0.02, −0.01, 0.005), component 1 only a slope of 0.015 on z. The
    /// motion sweeps ±2 in every axis.
    #[test]
    fn with_motion_the_offset_follows_the_fused_value() {
        let mut o = ParityOffset::with_motion(2000);
        let mut plain = ParityOffset::new(2000);
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut noise = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            (rng >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let truth = |x: &[f64; 3]| {
            let mut p = [0.0; MAX_PARITY];
            p[0] = 0.03 + 0.02 * x[0] - 0.01 * x[1] + 0.005 * x[2];
            p[1] = 0.015 * x[2];
            p
        };
        for k in 0..20_000u64 {
            let t = k as f64 * 0.001;
            let x = [
                2.0 * (1.3 * t).sin(),
                2.0 * (0.7 * t).cos(),
                2.0 * (2.1 * t).sin(),
            ];
            let mut p = truth(&x);
            p[0] += 0.01 * 3.46 * noise();
            p[1] += 0.01 * 3.46 * noise();
            let seen = (k < 1000).then_some(k);
            o.update(&p, &x, 2, seen, 1e-4);
            plain.update(&p, &x, 2, seen, 1e-4);
        }
        let x = [1.5, -1.0, 0.5];
        let (learnt, expected) = (o.at(&x, 2), truth(&x));
        for k in 0..2 {
            assert!(
                (learnt[k] - expected[k]).abs() < 2e-3,
                "{k}: {learnt:?} against {expected:?}"
            );
        }
        assert!(
            (o.slopes()[0][0] - 0.02).abs() < 1e-3,
            "{:?}",
            o.slopes()[0]
        );
        // The mean alone misses the motion's share by most of it.
        assert!((plain.at(&x, 2)[0] - expected[0]).abs() > 0.02);
        // Moving the constant keeps the slopes, and the next sample continues from both.
        let mut moved = o;
        moved.set_mean([0.0; MAX_PARITY]);
        assert_eq!(moved.slopes(), o.slopes());
        moved.update(&truth(&x), &x, 2, None, 1e-4);
        assert!((moved.slopes()[0][0] - o.slopes()[0][0]).abs() < 1e-3);
    }

    #[test]
    fn before_any_motion_the_slopes_stay_at_their_prior() {
        let mut o = ParityOffset::with_motion(1000);
        let mut p = [0.0; MAX_PARITY];
        p[0] = 0.2;
        for k in 0..500u64 {
            o.update(&p, &[0.0, 0.0, -9.8], 1, Some(k), 1e-4);
        }
        // Constant x: the slope along it and the constant are one; the prior keeps the slope
        // small and the offset at that x is the mean.
        assert!((o.at(&[0.0, 0.0, -9.8], 1)[0] - 0.2).abs() < 1e-6);
        assert!(o.slopes()[0][2].abs() < 0.02, "{:?}", o.slopes()[0]);
        assert_eq!(o.slopes()[0][0], 0.0);
    }
}
