//! A pitot airspeed sensor as an aiding source (`[navigator.airspeed]`, off by default): the
//! differential pressure q gives the true airspeed `V = √(2 (q − q₀) / ρ)`, with ρ the ISA density
//! at the filter's altitude (sea-level pressure 101 325 Pa) and q₀ the known zero offset.
//!
//! **Zero wind is assumed**: there are no wind states, so the airspeed is taken as the body-x
//! component of the filter's velocity over the ground, `V = (Ĉᵀ v̂)_x`. In calm air this bounds the
//! along-track velocity, and with the heading and the turns the horizontal velocity, when no GNSS
//! aids the filter; in wind, the wind's component along the nose becomes a velocity error and the
//! position drifts with the wind. Readings below `min_airspeed_mps` (parked, the take-off roll)
//! are skipped ([`AidingOutcome::Skipped`]; they still count as readings, so a parked vehicle's
//! sensor is not an outage): there the square root amplifies the sensor's noise and offset.
//!
//! Readings arrive on their own topic, like the barometer's, and are applied to the filter's
//! current state; one further than `max_lag_s` from the navigation time is dropped.

use ipc_types::{RawAirspeed, integrity_reason as why};
use nalgebra::{Matrix3, SMatrix, SVector, Vector1, Vector3};
use serde::{Deserialize, Serialize};

use crate::aiding::context::AidingContext;
use crate::aiding::outcome::AidingOutcome;
use crate::aiding::source::stream_aiding_sensor;
use crate::checks::positive;
use crate::ekf::{ATT, AidingSource, Linearised, STATES, VEL};

/// Sea-level pressure of the atmosphere the density is taken from, Pa (the ISA's: the
/// navigator does not know the day's QNH; 1 % off in pressure is 0.5 % in airspeed).
const DENSITY_QNH_PA: f64 = rins_earth::isa::P0_STANDARD_PA;

/// Settings of the airspeed aiding (`[navigator.airspeed]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AirspeedAidingConfig {
    /// Apply airspeed updates.
    pub enabled: bool,
    /// σ of the airspeed as a measure of the body-x velocity, m/s: the sensor's noise, and the
    /// wind and sideslip the model leaves out.
    pub sigma_mps: f64,
    /// The sensor's known zero offset, Pa, taken off every reading.
    pub offset_pa: f64,
    /// Readings of a lower airspeed are skipped, m/s.
    pub min_airspeed_mps: f64,
    /// Innovation gate (Mahalanobis distance).
    pub gate: f64,
    /// Largest accepted |reading time − navigation time|, s.
    pub max_lag_s: f64,
}

impl Default for AirspeedAidingConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            sigma_mps: 1.0,
            offset_pa: 0.0,
            min_airspeed_mps: 8.0,
            gate: 5.0,
            max_lag_s: 0.1,
        }
    }
}

impl AirspeedAidingConfig {
    /// `(field, value)` of the first out-of-range parameter.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        positive("sigma_mps", self.sigma_mps)?;
        if !(self.offset_pa.is_finite() && self.offset_pa.abs() <= 1000.0) {
            return Err(("offset_pa", self.offset_pa));
        }
        positive("min_airspeed_mps", self.min_airspeed_mps)?;
        positive("gate", self.gate)?;
        positive("max_lag_s", self.max_lag_s)
    }

    /// The true airspeed of differential pressure `diff_pressure_pa` at altitude `alt_m`, m/s;
    /// `None` below `min_airspeed_mps` (or for a pressure that is not a number).
    pub fn airspeed_mps(&self, diff_pressure_pa: f64, alt_m: f64) -> Option<f64> {
        let q = diff_pressure_pa - self.offset_pa;
        let rho = rins_earth::isa::density_kg_m3(alt_m, DENSITY_QNH_PA);
        let v = (2.0 * q.max(0.0) / rho).sqrt();
        (v.is_finite() && v >= self.min_airspeed_mps).then_some(v)
    }
}

stream_aiding_sensor!(
    AirspeedAidingConfig => Airspeed,
    inconsistent: why::AIRSPEED_INCONSISTENT,
    section: "navigator.airspeed",
    range: "out of range (|offset_pa| <= 1000, others finite and > 0)",
);

/// The predicted body-x velocity `u = (Ĉᵀ v̂)_x` of attitude `c` (body → NED) and velocity `v`
/// (NED), with its Jacobian in the filter's error convention (`C = (I + [δθ×]) Ĉ`,
/// `v = v̂ + δv`): `u ≈ x̂ᵀ v̂ + x̂ᵀ δv + x̂ᵀ [v̂×] δθ` with `x̂ = Ĉ e_x` the body x axis in NED, so
/// `∂u/∂δv = x̂ᵀ` and `∂u/∂δθ = (x̂ × v̂)ᵀ`.
pub fn body_x_velocity(c: &Matrix3<f64>, v: &Vector3<f64>) -> (f64, SMatrix<f64, 1, STATES>) {
    let x = c.column(0).into_owned();
    let mut h = SMatrix::<f64, 1, STATES>::zeros();
    let d_att = x.cross(v);
    for k in 0..3 {
        h[(0, VEL + k)] = x[k];
        h[(0, ATT + k)] = d_att[k];
    }
    (x.dot(v), h)
}

/// One pitot differential pressure.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AirspeedReading {
    /// Device time, µs.
    pub t_us: u64,
    /// Differential pressure, Pa.
    pub diff_pressure_pa: f64,
}

impl AirspeedReading {
    /// A raw airspeed sample as the sensor block publishes it.
    pub fn from_raw(airspeed: &RawAirspeed) -> Self {
        Self {
            t_us: airspeed.header.origin_device_time_us,
            diff_pressure_pa: f64::from(airspeed.diff_pressure_pa),
        }
    }
}

/// The airspeed aiding: its settings (it keeps nothing between readings).
#[derive(Debug, Clone)]
pub(crate) struct AirspeedAiding {
    config: AirspeedAidingConfig,
}

impl AirspeedAiding {
    pub(crate) fn new(config: AirspeedAidingConfig) -> Self {
        Self { config }
    }

    /// One differential pressure (Pa) at device time `t_us`: skipped before alignment, when
    /// disabled, too old or too slow; else one update of the body-x velocity.
    pub(crate) fn on_reading(
        &self,
        ctx: &mut AidingContext<'_>,
        r: AirspeedReading,
    ) -> AidingOutcome {
        let AirspeedReading {
            t_us,
            diff_pressure_pa,
        } = r;
        let c = self.config;
        if !diff_pressure_pa.is_finite() {
            return AidingOutcome::Skipped;
        }
        ctx.note_reading(AidingSource::Airspeed, t_us);
        let now_us = ctx.time_us();
        let Some(ekf) = ctx.filter_mut() else {
            return AidingOutcome::Skipped;
        };
        if !c.enabled {
            return AidingOutcome::Skipped;
        }
        let lag_s = now_us.map_or(f64::INFINITY, |n| n.abs_diff(t_us) as f64 * 1e-6);
        if lag_s > c.max_lag_s {
            return AidingOutcome::Skipped;
        }
        let Some(airspeed) = c.airspeed_mps(diff_pressure_pa, ekf.state().alt) else {
            return AidingOutcome::Skipped;
        };
        let attitude = ekf.state().attitude.to_rotation_matrix().into_inner();
        let (predicted, h) = body_x_velocity(&attitude, &ekf.state().velocity_ned);
        let m = Linearised {
            h,
            innovation: SVector::<f64, 1>::new(airspeed - predicted),
            r: SMatrix::from(Vector1::new(c.sigma_mps * c.sigma_mps)),
        };
        let outcome = ekf.apply(AidingSource::Airspeed, &m, c.gate);
        ctx.book_update(AidingSource::Airspeed, t_us, outcome, 1);
        if ctx.wants_reset(AidingSource::Airspeed, t_us) {
            reset_along_nose(ctx, t_us, airspeed, c.sigma_mps);
            return AidingOutcome::Reset;
        }
        AidingOutcome::Update(outcome)
    }
}

/// Every airspeed has been gated out for the persistence time: the filter's velocity is wrong
/// (it integrated something that was not motion), not the pitot. The velocity's component along
/// the nose is re-set to the airspeed, and the velocity's correlations dropped with a variance
/// that covers the other components' error as large as that correction.
fn reset_along_nose(ctx: &mut AidingContext<'_>, t_us: u64, airspeed: f64, sigma_mps: f64) {
    let Some(ekf) = ctx.filter_mut() else {
        return;
    };
    let attitude = ekf.state().attitude.to_rotation_matrix().into_inner();
    let x = attitude.column(0).into_owned();
    let v = ekf.state().velocity_ned;
    let correction = airspeed - x.dot(&v);
    ekf.state_mut().velocity_ned = v + x * correction;
    let variance = sigma_mps * sigma_mps + correction * correction;
    for k in 0..3 {
        ekf.reset_component(VEL + k, variance);
    }
    ctx.book_reset(AidingSource::Airspeed, t_us);
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Rotation3, UnitQuaternion};

    /// `u(C, v) = (Cᵀ v)_x`, evaluated exactly.
    fn body_x(c: &Matrix3<f64>, v: &Vector3<f64>) -> f64 {
        (c.transpose() * v).x
    }

    #[test]
    fn the_jacobian_matches_finite_differences_of_the_error_convention() {
        let c = UnitQuaternion::from_euler_angles(0.3, -0.2, 2.1)
            .to_rotation_matrix()
            .into_inner();
        let v = Vector3::new(-9.0, 12.0, 1.5);
        let (u, h) = body_x_velocity(&c, &v);
        assert!((u - body_x(&c, &v)).abs() < 1e-12);
        let eps = 1e-6;
        for k in 0..3 {
            // δθ_k: C = exp([δθ×]) Ĉ.
            let mut d = Vector3::zeros();
            d[k] = eps;
            let c_true = Rotation3::new(d).into_inner() * c;
            let numeric = (body_x(&c_true, &v) - u) / eps;
            assert!((numeric - h[(0, ATT + k)]).abs() < 1e-4, "δθ{k}");
            // δv_k: v = v̂ + δv.
            let numeric = (body_x(&c, &(v + d)) - u) / eps;
            assert!((numeric - h[(0, VEL + k)]).abs() < 1e-6, "δv{k}");
        }
        // Nothing else is measured.
        for j in (0..STATES).filter(|j| !(ATT..ATT + 3).contains(j) && !(VEL..VEL + 3).contains(j))
        {
            assert_eq!(h[(0, j)], 0.0);
        }
    }

    #[test]
    fn the_airspeed_inverts_the_dynamic_pressure_and_low_ones_are_refused() {
        let c = AirspeedAidingConfig {
            offset_pa: 2.0,
            ..AirspeedAidingConfig::default()
        };
        let rho = rins_earth::isa::density_kg_m3(500.0, DENSITY_QNH_PA);
        let q = 0.5 * rho * 15.0 * 15.0;
        let v = c.airspeed_mps(q + 2.0, 500.0).unwrap();
        assert!((v - 15.0).abs() < 1e-9, "{v}");
        assert_eq!(c.airspeed_mps(0.5 * rho * 7.9 * 7.9 + 2.0, 500.0), None);
        assert_eq!(c.airspeed_mps(-30.0, 500.0), None);
        assert_eq!(c.airspeed_mps(f64::NAN, 500.0), None);
    }

    #[test]
    fn bad_settings_are_named() {
        let bad = AirspeedAidingConfig {
            sigma_mps: 0.0,
            ..AirspeedAidingConfig::default()
        };
        assert_eq!(bad.check(), Err(("sigma_mps", 0.0)));
        let bad = AirspeedAidingConfig {
            offset_pa: f64::INFINITY,
            ..AirspeedAidingConfig::default()
        };
        assert_eq!(bad.check(), Err(("offset_pa", f64::INFINITY)));
        assert_eq!(AirspeedAidingConfig::default().check(), Ok(()));
    }
}
