//! What the filter's last prediction did, kept so that a smoother can run over the filter's
//! history afterwards (see [`crate::smoother`]): the transition `Φ = I + F Δt` (as its inputs),
//! the predicted covariance `P⁻`, and the sum of the corrections injected since.

use nalgebra::{Matrix3, SVector};

use super::{ATT, BA, BG, Covariance, POS, STATES, VEL};

/// One prediction step of the error filter and the corrections that followed it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictionRecord {
    /// Body-to-NED rotation the step was linearised at.
    pub(super) c: Matrix3<f64>,
    /// `[fⁿ×]` of the step.
    pub(super) f_skew: Matrix3<f64>,
    /// The step's length, s.
    pub(super) dt_s: f64,
    /// Covariance after the prediction, before any update.
    pub(super) prior: Covariance,
    /// Sum of the error-state corrections injected since the prediction (first order: each is
    /// small, so their composition is their sum).
    pub(super) injected: SVector<f64, STATES>,
}

impl Default for PredictionRecord {
    fn default() -> Self {
        Self {
            c: Matrix3::identity(),
            f_skew: Matrix3::zeros(),
            dt_s: 0.0,
            prior: Covariance::zeros(),
            injected: SVector::zeros(),
        }
    }
}

impl PredictionRecord {
    /// `Φ = I + F Δt`, the transition the covariance was predicted with (see the module docs of
    /// [`super`] for `F`).
    pub fn transition(&self) -> Covariance {
        let mut phi = Covariance::identity();
        let dt = self.dt_s;
        phi.fixed_view_mut::<3, 3>(ATT, BG)
            .copy_from(&(-self.c * dt));
        phi.fixed_view_mut::<3, 3>(VEL, ATT)
            .copy_from(&(-self.f_skew * dt));
        phi.fixed_view_mut::<3, 3>(VEL, BA)
            .copy_from(&(-self.c * dt));
        phi.fixed_view_mut::<3, 3>(POS, VEL)
            .copy_from(&(Matrix3::identity() * dt));
        phi
    }

    /// The covariance after the prediction, before any update.
    pub fn prior(&self) -> &Covariance {
        &self.prior
    }

    /// The corrections injected since the prediction, error-state order.
    pub fn injected(&self) -> &SVector<f64, STATES> {
        &self.injected
    }

    /// The step's length, s.
    pub fn dt_s(&self) -> f64 {
        self.dt_s
    }
}
