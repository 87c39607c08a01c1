//! Error-state extended Kalman filter (docs/design.md §6.4): a 15-state error filter around the quaternion
//! strapdown mechanisation.
//!
//! Error state `δx = [δθ, δv, δp, δb_g, δb_a]`:
//! * `δθ` — attitude error in the navigation (NED) frame: `C_true = (I + [δθ×]) Ĉ`;
//! * `δv` — velocity error, NED, m/s (`v_true = v̂ + δv`);
//! * `δp` — position error, NED metres (north, east, down) at the current position;
//! * `δb_g`, `δb_a` — gyro and accelerometer bias errors, body FRD (`b_true = b̂ + δb`).
//!
//! With `f̂ = f_meas − b̂_a` and `ω̂ = ω_meas − b̂_g` the linearised dynamics are
//! `δθ' = −Ĉ δb_g`, `δv' = −[fⁿ×] δθ − Ĉ δb_a`, `δp' = δv`, biases random walks (the signs
//! of \[R3\] eq. 14 with this document's error definitions). Transport-rate and Earth-rate terms are
//! left out: the missions are short (minutes) and local (kilometres), where they stay below the
//! sensor errors.
//!
//! The covariance is predicted on every IMU sample with `Φ = I + F Δt` and `Q_d = G Q Gᵀ Δt`;
//! updates use the Joseph form, gate the innovation by its Mahalanobis distance, then inject the
//! estimate into the nominal state and biases and reset `δx` to zero (the reset Jacobian is taken
//! as the identity, accurate to first order in the small corrections).

mod filter;
pub mod gnss;
mod linearised;
mod measurements;
mod noise;
mod prediction;

pub use filter::{AidingCounts, AidingSource, CorrectionTotals, ErrorStateEkf, UpdateOutcome};
pub use linearised::Linearised;
pub use measurements::heading_jacobian;
pub use noise::EkfNoise;
pub use prediction::PredictionRecord;

/// Size of the error state.
pub const STATES: usize = 15;
/// Index of the first component of each error block.
pub const ATT: usize = 0;
/// Velocity error block, NED, m/s.
pub const VEL: usize = 3;
/// Position error block, north/east/down metres.
pub const POS: usize = 6;
/// Gyro bias error block, body FRD, rad/s.
pub const BG: usize = 9;
/// Accelerometer bias error block, body FRD, m/s².
pub const BA: usize = 12;

/// Error-state covariance.
pub type Covariance = nalgebra::SMatrix<f64, STATES, STATES>;
