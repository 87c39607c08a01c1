//! Rauch–Tung–Striebel smoothing over the error-state filter's history, for the best trajectory
//! after a walk or a flight (offline: it keeps every step, so it is never on the live path).
//!
//! The filter resets its error estimate to zero after every injection, so the smoother works on
//! corrections to the stored nominal states (the error-state form of the RTS recursion used for
//! zero-velocity-aided inertial navigation by Colomar, Nilsson and Händel, "Smoothing for
//! ZUPT-aided INSs"). With `P⁺_k` the covariance after step `k`'s updates, `P⁻_{k+1}` and
//! `Φ_{k+1}` step `k + 1`'s prediction, `u_{k+1}` the corrections injected at step `k + 1`, and
//! `e_k` the smoothed correction to step `k`'s nominal state:
//!
//! `e_N = 0`, `e_k = P⁺_k Φ_{k+1}ᵀ (P⁻_{k+1})⁻¹ (u_{k+1} + e_{k+1})`.
//!
//! `u_{k+1} + e_{k+1}` is the smoothed error of step `k + 1`'s *predicted* nominal state (the
//! filter's own correction plus the smoother's), which the gain carries back one step.

use nalgebra::SVector;

use crate::ekf::{Covariance, ErrorStateEkf, POS, PredictionRecord, STATES, VEL};

/// One filter step as the smoother needs it.
#[derive(Debug, Clone)]
struct Step {
    prediction: PredictionRecord,
    posterior: Covariance,
    position_ned_m: [f64; 3],
    velocity_ned_mps: [f64; 3],
}

/// The smoothed trajectory, one entry per recorded step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Smoothed {
    /// Positions, the recorded frame (north, east, down metres), m.
    pub position_ned_m: Vec<[f64; 3]>,
    /// Velocities, NED, m/s.
    pub velocity_ned_mps: Vec<[f64; 3]>,
    /// Steps whose predicted covariance could not be inverted: the smoothed correction restarts
    /// from zero there (the filtered value is kept for that step and the ones before it until
    /// the next invertible step).
    pub singular_steps: usize,
}

/// The filter's history, recorded step by step while it runs, and the backward pass over it.
#[derive(Debug, Clone, Default)]
pub struct Smoother {
    steps: Vec<Step>,
}

impl Smoother {
    /// An empty history with room for `steps` steps.
    pub fn with_capacity(steps: usize) -> Self {
        Self {
            steps: Vec::with_capacity(steps),
        }
    }

    /// Records the filter after a sample whose prediction was applied, with its updates done:
    /// the last prediction, the covariance now, and the nominal position (in whatever local
    /// north-east-down frame the caller keeps, metres) and velocity.
    pub fn record(&mut self, ekf: &ErrorStateEkf, position_ned_m: [f64; 3]) {
        let v = ekf.state().velocity_ned;
        self.steps.push(Step {
            prediction: *ekf.last_prediction(),
            posterior: *ekf.covariance(),
            position_ned_m,
            velocity_ned_mps: [v.x, v.y, v.z],
        });
    }

    /// Steps recorded.
    pub fn len(&self) -> usize {
        self.steps.len()
    }

    /// Whether no step was recorded.
    pub fn is_empty(&self) -> bool {
        self.steps.is_empty()
    }

    /// The backward pass: smoothed positions and velocities of every recorded step.
    pub fn smooth(&self) -> Smoothed {
        let n = self.steps.len();
        let mut out = Smoothed {
            position_ned_m: vec![[0.0; 3]; n],
            velocity_ned_mps: vec![[0.0; 3]; n],
            singular_steps: 0,
        };
        let mut e = SVector::<f64, STATES>::zeros();
        for k in (0..n).rev() {
            if let Some(next) = self.steps.get(k + 1) {
                let carried = next.prediction.injected() + e;
                e = match next.prediction.prior().cholesky() {
                    Some(chol) => {
                        let w = chol.solve(&carried);
                        self.steps[k].posterior * (next.prediction.transition().transpose() * w)
                    }
                    None => {
                        out.singular_steps += 1;
                        SVector::zeros()
                    }
                };
                if !e.iter().all(|x| x.is_finite()) {
                    out.singular_steps += 1;
                    e = SVector::zeros();
                }
            }
            let step = &self.steps[k];
            for i in 0..3 {
                out.position_ned_m[k][i] = step.position_ned_m[i] + e[POS + i];
                out.velocity_ned_mps[k][i] = step.velocity_ned_mps[i] + e[VEL + i];
            }
        }
        out
    }
}
