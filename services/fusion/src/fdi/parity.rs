//! Parity space of one active channel set (docs/design.md §5).
//!
//! V is an orthonormal basis of the left null space of the active rows of H: (m×n_a) with
//! m = n_a − 3, `V H = 0`, `V Vᵀ = I`, taken from the last m left singular vectors of H (faer SVD).
//! The parity vector `p = V z` does not depend on the motion x, only on faults and noise; its noise
//! covariance is `S = V R Vᵀ` with `R = diag(σ_i²)`.
//!
//! **Whitening.** With `S = L Lᵀ` (Cholesky), the whitened parity `p' = L⁻¹ p = V_w z` with
//! `V_w = L⁻¹ V` has identity covariance, so the detection statistic is
//! `T = pᵀ S⁻¹ p = |p'|²` (χ²(m) when fault-free). `T` equals the weighted least-squares residual
//! `Σ r_i²/σ_i²` — the same number for any choice of basis.
//!
//! **GLT weighting.** A bias f on channel i moves p' by `f·w_i`, w_i the i-th column of V_w. The
//! generalised likelihood ratio of "bias on channel i" against "no fault", maximised over f, is
//! `(w_iᵀ p')² / (w_iᵀ w_i)` — the squared projection of the whitened parity on the fault
//! direction. This is the textbook `(v_iᵀ p)²/(v_iᵀ v_i)` (\[R12\]) made correct for unequal channel noise; with
//! equal σ it is that expression divided by σ², so the argmax is the same.
//!
//! Two channels whose columns are parallel ("twins") produce the same parity signature and cannot
//! be told apart by parity (every pair when m = 1, e.g. N = 4; aligned duplicate axes in stacked
//! triads); a channel with a zero column is invisible to parity. [`ParitySpace::twins`] records
//! this once per channel set using the structural tolerance of [`crate::capability`].

use super::MAX_PARITY;
use super::dense::{ParityMatrix, cholesky, forward_substitute};
use crate::capability::CAPABILITY_EPSILON;
use crate::geometry::{Geometry, MAX_CHANNELS, MIN_RECIPROCAL_CONDITION};
use faer::Mat;

/// Why a parity space cannot be built for a channel set.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ParityError {
    /// Fewer than three channels are active: no solution, no parity.
    #[error("only {active} active channels (mask {mask:#x}); at least 3 are needed")]
    InsufficientChannels {
        /// Active channels (bit i = channel i), bits beyond the geometry cleared.
        mask: u32,
        /// Number of active channels in the mask.
        active: usize,
    },
    /// The active axes are (nearly) coplanar, so the parity basis is ill-defined.
    #[error("active channels (mask {mask:#x}) do not span 3-D: σ3/σ1 of H = {ratio:.1e}")]
    RankDeficient {
        /// Active channels (bit i = channel i), bits beyond the geometry cleared.
        mask: u32,
        /// Smallest over largest singular value of the active rows of H.
        ratio: f64,
    },
    /// The SVD of the active rows of H did not converge.
    #[error("singular value decomposition of the active rows of H did not converge")]
    Decomposition,
    /// A channel's noise variance is zero, negative or not finite.
    #[error("noise variance of channel {channel} = {value}: must be finite and > 0")]
    InvalidVariance {
        /// 0-based index of the offending channel.
        channel: usize,
        /// The variance given, (rad/s)² or (m/s²)².
        value: f64,
    },
}

/// Parity basis, whitening and isolation geometry of one active channel set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParitySpace {
    mask: u32,
    n_active: usize,
    active: [u8; MAX_CHANNELS],
    dim: usize,
    /// Rows of V, indexed by channel (zero for inactive channels).
    basis: [[f64; MAX_CHANNELS]; MAX_PARITY],
    /// V R Vᵀ from the configured channel noise.
    configured_covariance: ParityMatrix,
    /// Cholesky factor L of the parity noise covariance in use.
    factor: ParityMatrix,
    /// Rows of V_w = L⁻¹ V for the noise covariance in use.
    whitened: [[f64; MAX_CHANNELS]; MAX_PARITY],
    /// |w_i|² per channel.
    column_norm2: [f64; MAX_CHANNELS],
    /// Channels whose parity column is parallel to channel i's (including i); 0 when channel i
    /// is invisible to parity or inactive.
    twins: [u32; MAX_CHANNELS],
}

impl ParitySpace {
    /// Builds the parity space of the channels of `geometry` selected by `mask` (bits at or above
    /// N ignored) with per-channel noise variances `variances` (N entries). Allocates (SVD):
    /// call at construction and reconfiguration only.
    pub fn new(geometry: &Geometry, mask: u32, variances: &[f64]) -> Result<Self, ParityError> {
        let mask = mask & geometry.full_mask();
        let axes = geometry.axes();
        for i in (0..geometry.n()).filter(|i| mask & (1 << i) != 0) {
            let value = variances.get(i).copied().unwrap_or(f64::NAN);
            if !(value.is_finite() && value > 0.0) {
                return Err(ParityError::InvalidVariance { channel: i, value });
            }
        }
        let (active, n_active) = geometry
            .active_channels(mask)
            .map_err(|active| ParityError::InsufficientChannels { mask, active })?;
        let h = Mat::<f64>::from_fn(n_active, 3, |r, c| axes[usize::from(active[r])][c]);
        let svd = h.svd().map_err(|_| ParityError::Decomposition)?;
        let s = svd.S().column_vector();
        let ratio = s[2] / s[0];
        // σ3/σ1 of H is the square root of λmin/λmax of HᵀH, the crate-wide conditioning limit.
        if !(ratio.is_finite() && ratio * ratio >= MIN_RECIPROCAL_CONDITION) {
            return Err(ParityError::RankDeficient { mask, ratio });
        }
        let u = svd.U();
        let dim = n_active - 3;
        let mut basis = [[0.0; MAX_CHANNELS]; MAX_PARITY];
        for (r, row) in basis.iter_mut().enumerate().take(dim) {
            for (k, &ch) in active[..n_active].iter().enumerate() {
                row[usize::from(ch)] = u[(k, 3 + r)];
            }
        }
        let mut configured_covariance = [[0.0; MAX_PARITY]; MAX_PARITY];
        for a in 0..dim {
            for b in 0..dim {
                configured_covariance[a][b] = active[..n_active]
                    .iter()
                    .map(|&ch| {
                        let ch = usize::from(ch);
                        basis[a][ch] * basis[b][ch] * variances[ch]
                    })
                    .sum();
            }
        }
        let mut space = Self {
            mask,
            n_active,
            active,
            dim,
            basis,
            configured_covariance,
            factor: [[0.0; MAX_PARITY]; MAX_PARITY],
            whitened: [[0.0; MAX_CHANNELS]; MAX_PARITY],
            column_norm2: [0.0; MAX_CHANNELS],
            twins: [0; MAX_CHANNELS],
        };
        space.find_twins();
        // V R Vᵀ of an orthonormal V and positive R is positive definite.
        if !space.set_noise_covariance(&configured_covariance) {
            return Err(ParityError::Decomposition);
        }
        Ok(space)
    }

    /// Structural isolation geometry from the unwhitened columns (parallelism is invariant under
    /// the whitening, an invertible map).
    fn find_twins(&mut self) {
        let column = |ch: usize| -> [f64; MAX_PARITY] {
            std::array::from_fn(|r| if r < self.dim { self.basis[r][ch] } else { 0.0 })
        };
        let dot = |a: &[f64; MAX_PARITY], b: &[f64; MAX_PARITY]| -> f64 {
            a.iter().zip(b).map(|(x, y)| x * y).sum()
        };
        for &i in &self.active[..self.n_active] {
            let ci = column(usize::from(i));
            let nii = dot(&ci, &ci);
            // |v_i|² = P_ii, the diagonal of the parity projector.
            if nii <= CAPABILITY_EPSILON {
                continue;
            }
            let mut twins = 0;
            for &j in &self.active[..self.n_active] {
                let cj = column(usize::from(j));
                let njj = dot(&cj, &cj);
                if njj > CAPABILITY_EPSILON
                    && dot(&ci, &cj).abs() >= (nii * njj).sqrt() * (1.0 - CAPABILITY_EPSILON)
                {
                    twins |= 1 << j;
                }
            }
            self.twins[usize::from(i)] = twins;
        }
    }

    /// Whitens with the parity noise covariance `s` (m×m, top-left block) instead of the
    /// configured one. Returns false (and changes nothing) when `s` is not positive definite.
    pub fn set_noise_covariance(&mut self, s: &ParityMatrix) -> bool {
        let Some(l) = cholesky(s, self.dim) else {
            return self.dim == 0;
        };
        let mut whitened = [[0.0; MAX_CHANNELS]; MAX_PARITY];
        let mut column_norm2 = [0.0; MAX_CHANNELS];
        for &ch in &self.active[..self.n_active] {
            let ch = usize::from(ch);
            let mut col: [f64; MAX_PARITY] =
                std::array::from_fn(|r| if r < self.dim { self.basis[r][ch] } else { 0.0 });
            forward_substitute(&l, self.dim, &mut col);
            for (r, row) in whitened.iter_mut().enumerate().take(self.dim) {
                row[ch] = col[r];
            }
            column_norm2[ch] = col[..self.dim].iter().map(|c| c * c).sum();
        }
        self.factor = l;
        self.whitened = whitened;
        self.column_norm2 = column_norm2;
        true
    }

    /// Mean variance of the parity noise in use, `tr(L Lᵀ) / m` (0 without parity). V has
    /// orthonormal rows, so a variance v added to every channel adds v to this.
    pub fn mean_noise_variance(&self) -> f64 {
        if self.dim == 0 {
            return 0.0;
        }
        let trace: f64 = self.factor[..self.dim]
            .iter()
            .map(|row| row[..self.dim].iter().map(|v| v * v).sum::<f64>())
            .sum();
        trace / self.dim as f64
    }

    /// Raw parity `p = V z` into `p[..m]` (z indexed by channel; inactive entries never read).
    pub fn parity(&self, z: &[f64; MAX_CHANNELS], p: &mut [f64; MAX_PARITY]) {
        for (pr, row) in p.iter_mut().zip(&self.basis).take(self.dim) {
            *pr = self.active[..self.n_active]
                .iter()
                .map(|&ch| row[usize::from(ch)] * z[usize::from(ch)])
                .sum();
        }
    }

    /// Whitens a raw (offset-corrected) parity vector: `pw = L⁻¹ p`; returns the test statistic
    /// `T = |pw|² = pᵀ S⁻¹ p`.
    pub fn whiten(&self, p: &[f64; MAX_PARITY], pw: &mut [f64; MAX_PARITY]) -> f64 {
        *pw = *p;
        forward_substitute(&self.factor, self.dim, pw);
        pw[..self.dim].iter().map(|v| v * v).sum()
    }

    /// Whitened parity `p' = V_w z = L⁻¹ V z` into `pw[..m]` (no offset); returns `T = |p'|²`.
    pub fn whitened_parity(&self, z: &[f64; MAX_CHANNELS], pw: &mut [f64; MAX_PARITY]) -> f64 {
        let mut p = [0.0; MAX_PARITY];
        self.parity(z, &mut p);
        self.whiten(&p, pw)
    }

    /// The parity vector `b` of `old` (another active set of the same geometry) expressed in this
    /// space: `V' Vᵀ b`. Exact for a channel-bias offset b = Vβ, because V'β only sees the
    /// parity-visible part Pβ = Vᵀb of β (see [`super::offset`]).
    pub fn carry_over(&self, old: &ParitySpace, b: &[f64; MAX_PARITY]) -> [f64; MAX_PARITY] {
        let beta = old.to_channels(b);
        let mut out = [0.0; MAX_PARITY];
        self.parity(&beta, &mut out);
        out
    }

    /// The channel values `Vᵀ b` whose parity is `b` (V has orthonormal rows): a parity-domain
    /// quantity, such as the learnt offset, carried in channel terms where no parity space exists.
    pub fn to_channels(&self, b: &[f64; MAX_PARITY]) -> [f64; MAX_CHANNELS] {
        let mut beta = [0.0; MAX_CHANNELS];
        for (row, br) in self.basis.iter().zip(b).take(self.dim) {
            for (x, v) in beta.iter_mut().zip(row) {
                *x += br * v;
            }
        }
        beta
    }

    /// GLT scores `(w_iᵀ p')² / (w_iᵀ w_i)` of every active channel visible to parity for the
    /// whitened parity `pw`; other entries 0. Returns the channel with the highest score.
    pub fn glt_scores(
        &self,
        pw: &[f64; MAX_PARITY],
        scores: &mut [f64; MAX_CHANNELS],
    ) -> Option<usize> {
        *scores = [0.0; MAX_CHANNELS];
        let mut best: Option<usize> = None;
        for &ch in &self.active[..self.n_active] {
            let ch = usize::from(ch);
            if self.twins[ch] == 0 {
                continue;
            }
            let proj: f64 = (0..self.dim).map(|r| self.whitened[r][ch] * pw[r]).sum();
            scores[ch] = proj * proj / self.column_norm2[ch];
            if best.is_none_or(|b| scores[ch] > scores[b]) {
                best = Some(ch);
            }
        }
        best
    }

    /// Channels of the set (bit i = channel i).
    pub fn mask(&self) -> u32 {
        self.mask
    }

    /// Parity dimension m = n_active − 3 (0: no parity).
    pub fn dimension(&self) -> usize {
        self.dim
    }

    /// The m rows of V, each indexed by channel (zero for inactive channels).
    pub fn basis(&self) -> &[[f64; MAX_CHANNELS]] {
        &self.basis[..self.dim]
    }

    /// The m rows of the whitened basis V_w = L⁻¹ V currently in use.
    pub fn whitened_basis(&self) -> &[[f64; MAX_CHANNELS]] {
        &self.whitened[..self.dim]
    }

    /// `V R Vᵀ` for the configured channel noise (top-left m×m block).
    pub fn configured_covariance(&self) -> &ParityMatrix {
        &self.configured_covariance
    }

    /// Channels whose parity signature is parallel to `channel`'s, including itself (bit mask);
    /// 0 when the channel is inactive or invisible to parity.
    pub fn twins(&self, channel: usize) -> u32 {
        self.twins.get(channel).copied().unwrap_or(0)
    }

    /// Active channels whose faults show in the parity vector.
    pub fn detectable_mask(&self) -> u32 {
        self.twins
            .iter()
            .enumerate()
            .filter(|(_, t)| **t != 0)
            .fold(0, |m, (i, _)| m | 1 << i)
    }
}
