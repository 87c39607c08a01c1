//! Sensitive-axis geometry of N redundant single-axis sensors (DESIGN §4.1).
//!
//! Sensor i measures `z_i = h_iᵀ x + ε_i`; the rows h_iᵀ form the N×3 matrix H. With equal noise σ
//! the least-squares estimate has covariance σ²(HᵀH)⁻¹, so diag((HᵀH)⁻¹) are the per-axis variance
//! factors of a layout and their square roots its noise amplification.

use crate::error::ConfigError;
use crate::linalg::{normal_matrix, reciprocal_condition};
use serde::Deserialize;

/// Most channels per sensor type (the IPC payloads are sized for this many).
pub const MAX_CHANNELS: usize = ipc_types::MAX_CHANNELS;
/// Fewest channels that still determine a 3-axis vector.
pub const MIN_CHANNELS: usize = 3;
/// Smallest accepted λ_min/λ_max of HᵀH (unit rows), i.e. cond(H) ≤ 1000. Below this the axes are
/// (nearly) coplanar and one body axis would be amplified by more than 1000× — useless in practice.
pub const MIN_RECIPROCAL_CONDITION: f64 = 1e-6;

/// Configured layout of the sensitive axes, in the body frame (FRD).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum GeometryConfig {
    /// n axes on a cone: `h_i = [cos α cos β_i, cos α sin β_i, sin α]`, `β_i = β0 + i·360°/n`.
    Pyramid {
        n: usize,
        /// Elevation α of every axis above the x-y plane, degrees, in (-90, 90).
        alpha_deg: f64,
        /// Azimuth β0 of the first axis, degrees.
        beta0_deg: f64,
    },
    /// Explicit axes, one `[x, y, z]` per channel (normalised on construction).
    Axes { axes: Vec<[f64; 3]> },
}

impl GeometryConfig {
    /// The seed's four-sensor pyramid: α = 28.7°, β0 = 45°.
    pub fn seed_pyramid() -> Self {
        GeometryConfig::Pyramid {
            n: 4,
            alpha_deg: 28.7,
            beta0_deg: 45.0,
        }
    }

    /// Validates the configuration and builds the geometry. Field names in errors are relative to
    /// this table; prefix them with [`ConfigError::within`].
    pub fn build(&self) -> Result<Geometry, ConfigError> {
        match self {
            GeometryConfig::Pyramid {
                n,
                alpha_deg,
                beta0_deg,
            } => pyramid(*n, *alpha_deg, *beta0_deg),
            GeometryConfig::Axes { axes } => Geometry::from_axes(axes),
        }
    }
}

impl Default for GeometryConfig {
    fn default() -> Self {
        Self::seed_pyramid()
    }
}

fn pyramid(n: usize, alpha_deg: f64, beta0_deg: f64) -> Result<Geometry, ConfigError> {
    if !(MIN_CHANNELS..=MAX_CHANNELS).contains(&n) {
        return Err(ConfigError::new(
            "n",
            n,
            format!("must be in {MIN_CHANNELS}..={MAX_CHANNELS}"),
        ));
    }
    if !(alpha_deg.is_finite() && alpha_deg > -90.0 && alpha_deg < 90.0) {
        return Err(ConfigError::new(
            "alpha_deg",
            alpha_deg,
            "must be in (-90, 90)",
        ));
    }
    if !beta0_deg.is_finite() {
        return Err(ConfigError::new("beta0_deg", beta0_deg, "must be finite"));
    }
    let (sa, ca) = alpha_deg.to_radians().sin_cos();
    let mut axes = [[0.0; 3]; MAX_CHANNELS];
    for (i, axis) in axes.iter_mut().take(n).enumerate() {
        let beta = (beta0_deg + i as f64 * 360.0 / n as f64).to_radians();
        let (sb, cb) = beta.sin_cos();
        *axis = [ca * cb, ca * sb, sa];
    }
    Geometry::from_axes(&axes[..n]).map_err(|e| {
        // A flat pyramid is the only way a valid n/α/β0 can fail: blame α.
        ConfigError::new("alpha_deg", alpha_deg, e.reason)
    })
}

/// N sensitive axes (unit vectors, rows of H) with their precomputed noise figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    n: usize,
    h: [[f64; 3]; MAX_CHANNELS],
    variance_factors: [f64; 3],
    reciprocal_condition: f64,
}

impl Geometry {
    /// Builds a geometry from 3..=16 axes, normalising each. Rejects zero or non-finite vectors and
    /// near-coplanar sets (see [`MIN_RECIPROCAL_CONDITION`]). Errors name `axes` or `axes[i]`.
    pub fn from_axes(axes: &[[f64; 3]]) -> Result<Self, ConfigError> {
        let n = axes.len();
        if !(MIN_CHANNELS..=MAX_CHANNELS).contains(&n) {
            return Err(ConfigError::new(
                "axes",
                format!("{n} axes"),
                format!("must have {MIN_CHANNELS}..={MAX_CHANNELS} axes"),
            ));
        }
        let mut h = [[0.0; 3]; MAX_CHANNELS];
        for (i, (row, a)) in h.iter_mut().zip(axes).enumerate() {
            let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if !(norm.is_finite() && norm > 1e-9) {
                return Err(ConfigError::new(
                    format!("axes[{i}]"),
                    format!("{a:?}"),
                    "must be a finite non-zero vector",
                ));
            }
            *row = [a[0] / norm, a[1] / norm, a[2] / norm];
        }
        let hth = normal_matrix(h[..n].iter().map(|r| (r, 1.0)));
        let rc = reciprocal_condition(&hth);
        if rc < MIN_RECIPROCAL_CONDITION {
            return Err(ConfigError::new(
                "axes",
                format!("{n} axes"),
                format!(
                    "axes are (nearly) coplanar: λmin/λmax of HᵀH = {rc:.1e} < {MIN_RECIPROCAL_CONDITION:.0e}"
                ),
            ));
        }
        let inv = hth
            .try_inverse()
            .ok_or_else(|| ConfigError::new("axes", format!("{n} axes"), "HᵀH is singular"))?;
        Ok(Self {
            n,
            h,
            variance_factors: [inv[(0, 0)], inv[(1, 1)], inv[(2, 2)]],
            reciprocal_condition: rc,
        })
    }

    /// Number of channels N.
    pub fn n(&self) -> usize {
        self.n
    }

    /// The N unit axes (rows of H).
    pub fn axes(&self) -> &[[f64; 3]] {
        &self.h[..self.n]
    }

    /// diag((HᵀH)⁻¹): per-axis variance of the least-squares estimate in units of the channel σ².
    pub fn variance_factors(&self) -> [f64; 3] {
        self.variance_factors
    }

    /// sqrt(diag((HᵀH)⁻¹)): per-axis noise standard deviation in units of the channel σ.
    pub fn noise_amplification(&self) -> [f64; 3] {
        self.variance_factors.map(f64::sqrt)
    }

    /// Dimension of the parity space, N − 3.
    pub fn parity_dimension(&self) -> usize {
        self.n - 3
    }

    /// λ_min/λ_max of HᵀH (1 for an isotropic layout such as the orthogonal triad).
    pub fn reciprocal_condition(&self) -> f64 {
        self.reciprocal_condition
    }

    /// Bitmask with one bit set per channel.
    pub fn full_mask(&self) -> u32 {
        channel_mask(self.n)
    }
}

/// Mask with the low `n` bits set.
pub(crate) fn channel_mask(n: usize) -> u32 {
    if n >= 32 { u32::MAX } else { (1u32 << n) - 1 }
}
