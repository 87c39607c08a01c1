//! Sensitive-axis geometry of N redundant single-axis sensors (docs/design.md §4).
//!
//! Sensor i measures `z_i = h_iᵀ x + ε_i`; the rows h_iᵀ form the N×3 matrix H. With equal noise σ
//! the least-squares estimate has covariance σ²(HᵀH)⁻¹, so diag((HᵀH)⁻¹) are the per-axis variance
//! factors of a layout and their square roots its noise amplification.
//!
//! Layouts (`kind` in the configuration): `pyramid` (n axes on a cone, the layout of \[R1\]), `axes`
//! (any 3..=16 vectors), `triad` (orthogonal, no redundancy), `dodecahedron` (6 face normals,
//! isotropic) and `stacked` (several triaxial IMUs, 3 rows each). What a layout allows for fault
//! detection and isolation is worked out from these rows by the `capability` module.

use crate::error::ConfigError;
use crate::linalg::{normal_matrix, reciprocal_condition};
use nalgebra::Rotation3;
use serde::{Deserialize, Serialize};

/// Most channels per sensor type (the IPC payloads are sized for this many).
pub const MAX_CHANNELS: usize = ipc_types::MAX_CHANNELS;
/// Fewest channels that still determine a 3-axis vector.
pub const MIN_CHANNELS: usize = 3;
/// Smallest accepted λ_min/λ_max of HᵀH (unit rows), i.e. cond(H) ≤ 1000. Below this the axes are
/// (nearly) coplanar and one body axis would be amplified by more than 1000× — useless in practice.
pub const MIN_RECIPROCAL_CONDITION: f64 = 1e-6;

/// Configured layout of the sensitive axes, in the body frame (FRD).
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase", deny_unknown_fields)]
pub enum GeometryConfig {
    /// n axes on a cone: `h_i = [cos α cos β_i, cos α sin β_i, sin α]`, `β_i = β0 + i·360°/n`.
    Pyramid {
        /// Number of axes, 3 to 16.
        n: usize,
        /// Elevation α of every axis above the x-y plane, degrees, in (-90, 90).
        alpha_deg: f64,
        /// Azimuth β0 of the first axis, degrees.
        beta0_deg: f64,
    },
    /// Explicit axes, one `[x, y, z]` unit vector per channel: a norm within
    /// [`UNIT_NORM_TOLERANCE`] of 1 (rounded decimals) is normalised, anything else refused.
    Axes {
        /// One sensitive axis per channel, body frame (FRD), in channel order.
        axes: Vec<[f64; 3]>,
    },
    /// Orthogonal triad: the body x, y and z axes (N = 3, no redundancy).
    Triad {},
    /// Six axes normal to the faces of a regular dodecahedron (see [`dodecahedron_axes`]):
    /// every pair 63.43° apart, HᵀH = 2I, per-axis variance factor 3/N = 0.5.
    Dodecahedron {},
    /// `count` triaxial IMUs whose x, y, z axes become consecutive rows (IMU k: rows 3k..3k+3).
    Stacked {
        /// Number of triads, 1..=5 (at most 16 rows).
        count: usize,
        /// Mounting of each IMU relative to the body as `[roll, pitch, yaw]` degrees (Z-Y-X
        /// Euler angles of the IMU→body rotation); empty = all aligned with the body.
        #[serde(default)]
        rotations_deg: Vec<[f64; 3]>,
    },
}

impl GeometryConfig {
    /// The four-sensor pyramid of \[R1\]: α = 28.7°, β0 = 45°.
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
            GeometryConfig::Axes { axes } => {
                check_unit_axes(axes)?;
                Geometry::from_axes(axes)
            }
            GeometryConfig::Triad {} => Geometry::from_axes(&TRIAD_AXES),
            GeometryConfig::Dodecahedron {} => Geometry::from_axes(&dodecahedron_axes()),
            GeometryConfig::Stacked {
                count,
                rotations_deg,
            } => stacked(*count, rotations_deg),
        }
    }
}

impl Default for GeometryConfig {
    fn default() -> Self {
        Self::seed_pyramid()
    }
}

/// How far from 1 the norm of a configured axis may be: decimals rounded to a few places are
/// normalised; a vector of another length is a mistake (a scale factor or a typing error would
/// otherwise be silently accepted as a direction).
pub const UNIT_NORM_TOLERANCE: f64 = 0.01;

/// Refuses a configured axis whose norm is not within [`UNIT_NORM_TOLERANCE`] of 1, naming it, its
/// value and its norm. A zero or non-finite vector is left to [`Geometry::from_axes`], which says so.
fn check_unit_axes(axes: &[[f64; 3]]) -> Result<(), ConfigError> {
    for (i, a) in axes.iter().enumerate() {
        let norm = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
        if norm.is_finite() && norm > 1e-9 && (norm - 1.0).abs() > UNIT_NORM_TOLERANCE {
            return Err(ConfigError::new(
                format!("axes[{i}]"),
                format!("[{}, {}, {}]", a[0], a[1], a[2]),
                format!("must be a unit vector (norm {})", round_for_display(norm)),
            ));
        }
    }
    Ok(())
}

/// `norm` with at most 4 decimals and no trailing zeros: `5`, `1.4142`.
fn round_for_display(norm: f64) -> f64 {
    (norm * 1e4).round() / 1e4
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

/// The orthogonal triad: body x (forward), y (right), z (down).
pub const TRIAD_AXES: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// Most triads a stacked layout can hold (3 rows each, at most [`MAX_CHANNELS`] rows).
pub const MAX_STACKED_TRIADS: usize = MAX_CHANNELS / 3;

/// The six face normals of a regular dodecahedron (the vertex pairs of the dual icosahedron):
/// `[±a, 0, b]`, `[0, b, ±a]`, `[b, ±a, 0]` with `a = 1/√(1+φ²)`, `b = φ/√(1+φ²)`, φ the golden
/// ratio, in that order. Each axis lies in one body coordinate plane, tilted by atan(1/φ) =
/// 31.72° from a body axis; every pair of axes (as lines) is 63.43° apart (|cos| = 1/√5).
/// The pattern is symmetric under the cyclic permutation x→y→z, hence HᵀH = 2I.
pub fn dodecahedron_axes() -> [[f64; 3]; 6] {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let norm = (1.0 + phi * phi).sqrt();
    let (a, b) = (1.0 / norm, phi / norm);
    [
        [a, 0.0, b],
        [-a, 0.0, b],
        [0.0, b, a],
        [0.0, b, -a],
        [b, a, 0.0],
        [b, -a, 0.0],
    ]
}

fn stacked(count: usize, rotations_deg: &[[f64; 3]]) -> Result<Geometry, ConfigError> {
    if !(1..=MAX_STACKED_TRIADS).contains(&count) {
        return Err(ConfigError::new(
            "count",
            count,
            format!(
                "must be in 1..={MAX_STACKED_TRIADS} (3 rows per triad, at most {MAX_CHANNELS} rows)"
            ),
        ));
    }
    if !(rotations_deg.is_empty() || rotations_deg.len() == count) {
        return Err(ConfigError::new(
            "rotations_deg",
            format!("{} entries", rotations_deg.len()),
            format!("must have {count} entries (one per triad) or be empty"),
        ));
    }
    if let Some((k, r)) = rotations_deg
        .iter()
        .enumerate()
        .find(|(_, r)| !r.iter().all(|a| a.is_finite()))
    {
        return Err(ConfigError::new(
            format!("rotations_deg[{k}]"),
            format!("{r:?}"),
            "must be finite [roll, pitch, yaw] degrees",
        ));
    }
    let mut axes = [[0.0; 3]; MAX_CHANNELS];
    for k in 0..count {
        let [roll, pitch, yaw] = rotations_deg.get(k).copied().unwrap_or([0.0; 3]);
        let rot =
            Rotation3::from_euler_angles(roll.to_radians(), pitch.to_radians(), yaw.to_radians());
        // IMU axis e_j seen in the body frame is column j of the IMU→body rotation.
        for j in 0..3 {
            let col = rot.matrix().column(j);
            axes[3 * k + j] = [col[0], col[1], col[2]];
        }
    }
    // Each triad alone spans 3-D, so a stacked layout is never rank deficient.
    Geometry::from_axes(&axes[..3 * count])
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

    /// The channels selected by `mask` (bits at or above N ignored) in ascending order, and how
    /// many they are; their count as the error when fewer than [`MIN_CHANNELS`] (nothing to
    /// solve for).
    pub fn active_channels(&self, mask: u32) -> Result<([u8; MAX_CHANNELS], usize), usize> {
        let mut active = [0u8; MAX_CHANNELS];
        let mut n_active = 0;
        for i in (0..self.n).filter(|i| mask & (1 << i) != 0) {
            active[n_active] = i as u8;
            n_active += 1;
        }
        if n_active < MIN_CHANNELS {
            return Err(n_active);
        }
        Ok((active, n_active))
    }
}

/// Mask with the low `n` bits set.
pub(crate) fn channel_mask(n: usize) -> u32 {
    if n >= 32 { u32::MAX } else { (1u32 << n) - 1 }
}
