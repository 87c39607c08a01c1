//! Weighted least squares for one active channel set (docs/design.md §4):
//! `x̂ = (HᵀWH)⁻¹ HᵀW z`, `cov(x̂) = (HᵀWH)⁻¹`, `W = diag(1/σ_i²)`.
//!
//! The gain G = (HᵀWH)⁻¹HᵀW is computed once per channel set so that a sample costs 3·N
//! multiply-adds and no allocation.

use crate::geometry::{Geometry, MAX_CHANNELS, MIN_RECIPROCAL_CONDITION};
use crate::linalg::{normal_matrix, reciprocal_condition};
use nalgebra::Matrix3;

/// Why a solver cannot be built for a channel set.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum WlsError {
    /// Fewer than three channels are active.
    #[error("only {active} active channels (mask {mask:#x}); at least 3 are needed")]
    InsufficientChannels {
        /// Active channels (bit i = channel i), bits beyond the geometry cleared.
        mask: u32,
        /// Number of active channels in the mask.
        active: usize,
    },
    /// The active axes are (nearly) coplanar: HᵀH is too ill-conditioned to invert (see
    /// [`MIN_RECIPROCAL_CONDITION`]).
    #[error(
        "active channels (mask {mask:#x}) are rank deficient: λmin/λmax of HᵀH = {reciprocal_condition:.1e}"
    )]
    RankDeficient {
        /// Active channels (bit i = channel i), bits beyond the geometry cleared.
        mask: u32,
        /// λ_min/λ_max of HᵀH over the active rows.
        reciprocal_condition: f64,
    },
    /// A channel's noise variance is zero, negative or not finite.
    #[error("noise variance of channel {channel} = {value}: must be finite and > 0")]
    InvalidVariance {
        /// 0-based index of the offending channel.
        channel: usize,
        /// The variance given, (rad/s)² or (m/s²)².
        value: f64,
    },
    /// The number of noise variances differs from the number of channels of the geometry.
    #[error("{given} noise variances given for {expected} channels")]
    VarianceCount {
        /// Channels of the geometry.
        expected: usize,
        /// Variances given.
        given: usize,
    },
}

/// Precomputed least-squares solution for one geometry and active-channel mask.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WlsSolver {
    mask: u32,
    n_active: usize,
    /// Channel index of the k-th active channel.
    active: [u8; MAX_CHANNELS],
    /// Column of G for the k-th active channel.
    gain: [[f64; 3]; MAX_CHANNELS],
    covariance: Matrix3<f64>,
    variance: [f64; 3],
}

impl WlsSolver {
    /// Builds the solver for the channels of `geometry` selected by `mask` (bit i = channel i; bits
    /// at or above N are ignored), with per-channel noise variances `variances` (N entries, SI²).
    pub fn new(geometry: &Geometry, mask: u32, variances: &[f64]) -> Result<Self, WlsError> {
        let n = geometry.n();
        if variances.len() != n {
            return Err(WlsError::VarianceCount {
                expected: n,
                given: variances.len(),
            });
        }
        if let Some((channel, &value)) = variances
            .iter()
            .enumerate()
            .find(|(_, v)| !(v.is_finite() && **v > 0.0))
        {
            return Err(WlsError::InvalidVariance { channel, value });
        }
        let mask = mask & geometry.full_mask();
        let axes = geometry.axes();
        let (active, n_active) = geometry
            .active_channels(mask)
            .map_err(|active| WlsError::InsufficientChannels { mask, active })?;
        let active_rows = || active[..n_active].iter().map(|&i| usize::from(i));

        // Conditioning is judged on the unweighted rows so that it means the same as for the
        // full geometry, independent of the noise units.
        let rc = reciprocal_condition(&normal_matrix(active_rows().map(|i| (&axes[i], 1.0))));
        let rank_deficient = WlsError::RankDeficient {
            mask,
            reciprocal_condition: rc,
        };
        if rc < MIN_RECIPROCAL_CONDITION {
            return Err(rank_deficient);
        }
        let htwh = normal_matrix(active_rows().map(|i| (&axes[i], 1.0 / variances[i])));
        let covariance = htwh.cholesky().ok_or(rank_deficient)?.inverse();

        let mut gain = [[0.0; 3]; MAX_CHANNELS];
        for (g, i) in gain.iter_mut().zip(active_rows()) {
            let h = nalgebra::Vector3::from(axes[i]);
            let col = covariance * h / variances[i];
            *g = [col[0], col[1], col[2]];
        }
        Ok(Self {
            mask,
            n_active,
            active,
            gain,
            covariance,
            variance: [covariance[(0, 0)], covariance[(1, 1)], covariance[(2, 2)]],
        })
    }

    /// Estimates x from the channel measurements `z` (indexed by channel; inactive entries are
    /// never read, so they may hold NaN). Returns the estimate and the variance of each axis.
    /// An active channel missing from `z` yields NaN.
    pub fn solve(&self, z: &[f64]) -> ([f64; 3], [f64; 3]) {
        let mut x = [0.0; 3];
        for (g, &i) in self.gain.iter().zip(&self.active).take(self.n_active) {
            let zi = z.get(usize::from(i)).copied().unwrap_or(f64::NAN);
            x[0] += g[0] * zi;
            x[1] += g[1] * zi;
            x[2] += g[2] * zi;
        }
        (x, self.variance)
    }

    /// Column of the gain G for `channel`: how a change of that channel's value moves the
    /// solution. `None` when the channel is not in the solution.
    pub fn gain_of(&self, channel: usize) -> Option<[f64; 3]> {
        self.active[..self.n_active]
            .iter()
            .position(|&i| usize::from(i) == channel)
            .map(|k| self.gain[k])
    }

    /// The channels this solver uses (bit i = channel i).
    pub fn mask(&self) -> u32 {
        self.mask
    }

    /// Number of channels used.
    pub fn active_count(&self) -> usize {
        self.n_active
    }

    /// Full solution covariance (HᵀWH)⁻¹, row-major.
    pub fn covariance(&self) -> [[f64; 3]; 3] {
        let c = &self.covariance;
        [
            [c[(0, 0)], c[(0, 1)], c[(0, 2)]],
            [c[(1, 0)], c[(1, 1)], c[(1, 2)]],
            [c[(2, 0)], c[(2, 1)], c[(2, 2)]],
        ]
    }
}
