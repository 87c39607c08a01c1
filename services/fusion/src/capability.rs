//! What a sensor geometry can do for fault detection and isolation (docs/design.md §4–5), decided
//! from the structure of H alone, without an SVD.
//!
//! The parity space (left null space of H) is the column space of the projector
//! `P = I − H(HᵀH)⁻¹Hᵀ`; with V an orthonormal parity basis, `P = VᵀV`, so `P_ij = v_iᵀ v_j` for the
//! columns v_i of V. A fault of size f on channel i moves the parity vector by `f·v_i`:
//! - channel i is *detectable* iff `v_i ≠ 0`, i.e. `P_ii > ε`;
//! - channels i and j are *distinguishable* iff v_i and v_j are not parallel, i.e.
//!   `|P_ij| < √(P_ii P_jj)·(1 − ε)` (their cosine is below 1).
//!
//! These are structural answers (noise-free, ε = [`CAPABILITY_EPSILON`]); how large a fault must be
//! to be detected at a given false-alarm rate is the detector's business.

use crate::geometry::{Geometry, MAX_CHANNELS, MIN_CHANNELS, MIN_RECIPROCAL_CONDITION};
use crate::linalg::{normal_matrix, reciprocal_condition};
use nalgebra::Vector3;
use serde::Serialize;

/// Relative tolerance of the structural checks: a parity column counts as zero when
/// `P_ii ≤ ε`, two columns as parallel when their |cosine| ≥ 1 − ε.
pub const CAPABILITY_EPSILON: f64 = 1e-6;

/// Noise figures and fault-handling abilities of a set of sensitive axes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Capability {
    /// Number of channels.
    pub n: usize,
    /// sqrt(diag((HᵀH)⁻¹)): per-axis σ of the least-squares estimate in units of the channel σ.
    pub noise_amplification: [f64; 3],
    /// diag((HᵀH)⁻¹): per-axis variance in units of the channel σ².
    pub variance_factors: [f64; 3],
    /// N − 3.
    pub parity_dimension: usize,
    /// A fault on any single channel shows in the parity vector (N ≥ 4, every `P_ii > ε`).
    pub detect: bool,
    /// The parity vector alone says which single channel failed (N ≥ 5, detect, and no two
    /// parity columns parallel).
    pub isolate_one: bool,
    /// After excluding any one channel the rest can still isolate one more (N ≥ 6).
    pub tolerate_two: bool,
}

impl Capability {
    /// Capability of all channels of `geometry`.
    pub fn of(geometry: &Geometry) -> Self {
        // A built geometry passed the conditioning check, so the full set always yields a value;
        // the fallback only keeps this total.
        Self::of_channels(geometry, geometry.full_mask()).unwrap_or(Self {
            n: geometry.n(),
            noise_amplification: geometry.noise_amplification(),
            variance_factors: geometry.variance_factors(),
            parity_dimension: geometry.parity_dimension(),
            detect: false,
            isolate_one: false,
            tolerate_two: false,
        })
    }

    /// Capability of the channels of `geometry` selected by `mask` (bit i = channel i; bits at or
    /// above N are ignored), e.g. what remains after exclusions. `None` when fewer than three
    /// channels remain or they do not span 3-D.
    pub fn of_channels(geometry: &Geometry, mask: u32) -> Option<Self> {
        let rows = Rows::select(geometry.axes(), mask & geometry.full_mask());
        let parity = Parity::of(&rows)?;
        let n = rows.n;
        let isolate_one = parity.isolates_one();
        let tolerate_two = isolate_one
            && n >= 6
            && (0..n).all(|k| Parity::of(&rows.without(k)).is_some_and(|p| p.isolates_one()));
        Some(Self {
            n,
            noise_amplification: parity.variance_factors.map(f64::sqrt),
            variance_factors: parity.variance_factors,
            parity_dimension: n - 3,
            detect: parity.detects(),
            isolate_one,
            tolerate_two,
        })
    }
}

/// Parity projector `P = I − H(HᵀH)⁻¹Hᵀ` of the rows `h` (row-major, only the first `n` rows and
/// columns meaningful), or `None` when fewer than three rows or they do not span 3-D.
pub fn parity_projector(h: &[[f64; 3]]) -> Option<[[f64; MAX_CHANNELS]; MAX_CHANNELS]> {
    if h.len() > MAX_CHANNELS {
        return None;
    }
    let mut rows = Rows {
        n: h.len(),
        h: [[0.0; 3]; MAX_CHANNELS],
    };
    rows.h[..h.len()].copy_from_slice(h);
    Parity::of(&rows).map(|p| p.p)
}

/// Up to 16 rows of H on the stack.
#[derive(Clone, Copy)]
struct Rows {
    n: usize,
    h: [[f64; 3]; MAX_CHANNELS],
}

impl Rows {
    fn select(axes: &[[f64; 3]], mask: u32) -> Self {
        let mut rows = Rows {
            n: 0,
            h: [[0.0; 3]; MAX_CHANNELS],
        };
        let selected = axes
            .iter()
            .enumerate()
            .filter(|(i, _)| mask & (1 << i) != 0)
            .map(|(_, a)| a);
        for a in selected {
            rows.h[rows.n] = *a;
            rows.n += 1;
        }
        rows
    }

    fn without(&self, k: usize) -> Self {
        let mut rows = Rows {
            n: 0,
            h: [[0.0; 3]; MAX_CHANNELS],
        };
        let kept = self.h[..self.n]
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != k)
            .map(|(_, a)| a);
        for a in kept {
            rows.h[rows.n] = *a;
            rows.n += 1;
        }
        rows
    }
}

struct Parity {
    n: usize,
    p: [[f64; MAX_CHANNELS]; MAX_CHANNELS],
    variance_factors: [f64; 3],
}

impl Parity {
    fn of(rows: &Rows) -> Option<Self> {
        let n = rows.n;
        if n < MIN_CHANNELS {
            return None;
        }
        let h = &rows.h[..n];
        let hth = normal_matrix(h.iter().map(|r| (r, 1.0)));
        if reciprocal_condition(&hth) < MIN_RECIPROCAL_CONDITION {
            return None;
        }
        let inv = hth.cholesky()?.inverse();
        let mut p = [[0.0; MAX_CHANNELS]; MAX_CHANNELS];
        for i in 0..n {
            let gi = inv * Vector3::from(h[i]);
            for j in 0..n {
                let delta = if i == j { 1.0 } else { 0.0 };
                p[i][j] = delta - Vector3::from(h[j]).dot(&gi);
            }
        }
        Some(Self {
            n,
            p,
            variance_factors: [inv[(0, 0)], inv[(1, 1)], inv[(2, 2)]],
        })
    }

    fn detects(&self) -> bool {
        self.n > MIN_CHANNELS && (0..self.n).all(|i| self.p[i][i] > CAPABILITY_EPSILON)
    }

    fn isolates_one(&self) -> bool {
        let p = &self.p;
        self.n >= 5
            && self.detects()
            && (0..self.n).all(|i| {
                (i + 1..self.n).all(|j| {
                    p[i][j].abs() < (p[i][i] * p[j][j]).sqrt() * (1.0 - CAPABILITY_EPSILON)
                })
            })
    }
}
