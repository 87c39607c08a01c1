//! GNSS position and velocity measurements of the antenna, which sits at lever arm `l` (body
//! FRD) from the IMU.
//!
//! Position: `p_ant = p + C l`. With `C = (I + [δθ×]) Ĉ`, `C l = Ĉ l + δθ × Ĉ l = Ĉ l − [(Ĉ l)×] δθ`,
//! so `H = [−[(Ĉ l)×], 0, I, 0, 0]`.
//! Velocity: `v_ant = v + C (ω × l)` with `ω = ω_m − b_g`; `δ(C (ω × l)) = −[(C (ω × l))×] δθ +
//! C [l×] δb_g` (`ω × l = −l × ω`, and `δω = −δb_g`), so `H = [−[(Ĉ(ω̂×l))×], I, 0, Ĉ[l×], 0]`.
//!
//! Both are evaluated at the measurement's own instant (a [`PastState`] from the history) and
//! applied to the present error state: the covariance of the present stands in for that of the
//! past, which over the receiver's latency (a tenth of a second) differs by one tenth of a second
//! of process noise.

use nalgebra::{Matrix3, SMatrix, Vector3};

use super::filter::skew;
use super::linearised::Linearised;
use super::{ATT, BG, POS, STATES, VEL};
use crate::state_history::PastState;

/// The antenna position measurement `(lat, lon, alt)` against the state `past`, with per-axis σ
/// (north and east `sigma_h_m`, down `sigma_v_m`); the innovation is in NED metres.
pub fn antenna_position(
    past: &PastState,
    measured: [f64; 3],
    lever_arm: &Vector3<f64>,
    sigma_h_m: f64,
    sigma_v_m: f64,
) -> Linearised<3> {
    let c = past.attitude.to_rotation_matrix().into_inner();
    let arm_ned = c * lever_arm;
    let [lat, lon, alt] = measured;
    let innovation = past.ned_to(lat, lon, alt) - arm_ned;
    let mut h = SMatrix::<f64, 3, STATES>::zeros();
    h.fixed_view_mut::<3, 3>(0, ATT)
        .copy_from(&(-skew(&arm_ned)));
    h.fixed_view_mut::<3, 3>(0, POS)
        .copy_from(&Matrix3::identity());
    let r = Matrix3::from_diagonal(&Vector3::new(
        sigma_h_m * sigma_h_m,
        sigma_h_m * sigma_h_m,
        sigma_v_m * sigma_v_m,
    ));
    Linearised { h, innovation, r }
}

/// The antenna velocity measurement (NED m/s) against the state `past`, σ `sigma_mps` per axis.
pub fn antenna_velocity(
    past: &PastState,
    measured_ned: [f64; 3],
    lever_arm: &Vector3<f64>,
    sigma_mps: f64,
) -> Linearised<3> {
    let c = past.attitude.to_rotation_matrix().into_inner();
    let arm_velocity = c * past.rate_body.cross(lever_arm);
    let innovation = Vector3::from(measured_ned) - (past.velocity_ned + arm_velocity);
    let mut h = SMatrix::<f64, 3, STATES>::zeros();
    h.fixed_view_mut::<3, 3>(0, ATT)
        .copy_from(&(-skew(&arm_velocity)));
    h.fixed_view_mut::<3, 3>(0, VEL)
        .copy_from(&Matrix3::identity());
    h.fixed_view_mut::<3, 3>(0, BG)
        .copy_from(&(c * skew(lever_arm)));
    let r = Matrix3::identity() * (sigma_mps * sigma_mps);
    Linearised { h, innovation, r }
}
