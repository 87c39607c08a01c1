//! The one path every aiding measurement takes into the filter: a source linearises its
//! measurement (Jacobian, innovation, noise) and hands it over with its innovation gate; the
//! filter tests it, applies it or gates it out, counts it for the source and says which.

use nalgebra::{SMatrix, SVector};

use super::STATES;
use super::filter::{AidingSource, ErrorStateEkf, UpdateOutcome};

/// One linearised measurement of `M` components: Jacobian, innovation `z − h(x̂)`, noise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linearised<const M: usize> {
    /// `∂h/∂δx`.
    pub h: SMatrix<f64, M, STATES>,
    /// `z − h(x̂)`.
    pub innovation: SVector<f64, M>,
    /// Measurement noise covariance.
    pub r: SMatrix<f64, M, M>,
}

impl ErrorStateEkf {
    /// Applies `m` for `source` when its squared Mahalanobis distance is at most `gate²` (see
    /// [`ErrorStateEkf::update`]).
    pub fn apply<const M: usize>(
        &mut self,
        source: AidingSource,
        m: &Linearised<M>,
        gate: f64,
    ) -> UpdateOutcome {
        self.update(source, &m.h, &m.innovation, &m.r, gate)
    }

    /// The innovation covariance of `m` and its squared Mahalanobis distance, nothing applied
    /// (see [`ErrorStateEkf::innovation_test`]).
    pub fn test<const M: usize>(&self, m: &Linearised<M>) -> Option<(SMatrix<f64, M, M>, f64)> {
        self.innovation_test(&m.h, &m.innovation, &m.r)
    }
}
