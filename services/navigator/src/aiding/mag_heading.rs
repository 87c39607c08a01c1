//! Magnetometer heading aiding with an adaptive measurement noise (docs/design.md §6.5; \[R2\], \[R3\]).
//!
//! **Measurement.** The calibrated body field is rotated into the navigation frame with the
//! filter's attitude; its azimuth `α = atan2(H_E, H_N)` is where the filter believes magnetic north
//! to be. With a heading error δ (estimate = true + δ) the estimated rotation turns the field by
//! δ too, so `α = D + δ` and the measured heading is `ψ_mag = ψ̂ − (α − D)` (D the declination).
//! Only roll and pitch enter it in the end, which is the tilt compensation of \[R3\] eq. 9.
//!
//! **Adaptive R (\[R2\]).** The magnetometer heading is only as good as two assumptions: the
//! accelerometer measures gravity alone (else the tilt used to level the field is wrong) and the
//! field is the undisturbed Earth field. Each is checked per sample against a tolerance — `| |f| −
//! g |`, `| |m| − |m_ref| |` and the dip angle's departure from the reference — and the largest
//! ratio `r` of departure to tolerance scales σ: `σ = σ₀` while `r ≤ 1`, `σ = σ₀ · inflation · r`
//! beyond. The reference magnitude and dip are those of the mean field in the alignment window.

use crate::checks::positive;
use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use crate::attitude::wrap_pi;

/// Settings of the magnetometer heading aiding (`[navigator.mag]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MagAidingConfig {
    /// Apply magnetometer heading updates.
    pub enabled: bool,
    /// Only during stance (the heading update, HUPT, of a foot-mounted unit: the foot is still,
    /// so the tilt is right and the field is read without motion).
    pub stance_only: bool,
    /// Heading σ σ₀ when the checks pass, degrees.
    pub sigma_deg: f64,
    /// Tolerance on `| |f| − g |`, m/s².
    pub specific_force_tolerance_mps2: f64,
    /// Tolerance on `| |m| − |m_ref| |`, µT.
    pub field_tolerance_ut: f64,
    /// Tolerance on the dip angle's departure from the reference, degrees.
    pub dip_tolerance_deg: f64,
    /// Extra factor on σ once a check fails.
    pub inflation: f64,
    /// Innovation gate (Mahalanobis distance).
    pub gate: f64,
    /// Apply at most this many updates per second (the magnetometer may run faster than the
    /// heading changes; 0 = every sample).
    pub max_rate_hz: f64,
}

impl Default for MagAidingConfig {
    fn default() -> Self {
        Self {
            enabled: true,
            stance_only: false,
            sigma_deg: 2.0,
            specific_force_tolerance_mps2: 0.5,
            field_tolerance_ut: 5.0,
            dip_tolerance_deg: 5.0,
            inflation: 10.0,
            gate: 5.0,
            max_rate_hz: 10.0,
        }
    }
}

impl MagAidingConfig {
    /// `(field, value)` of the first out-of-range parameter.
    pub fn check(&self) -> Result<(), (&'static str, f64)> {
        positive("sigma_deg", self.sigma_deg)?;
        positive(
            "specific_force_tolerance_mps2",
            self.specific_force_tolerance_mps2,
        )?;
        positive("field_tolerance_ut", self.field_tolerance_ut)?;
        positive("dip_tolerance_deg", self.dip_tolerance_deg)?;
        positive("gate", self.gate)?;
        if !(self.inflation.is_finite() && self.inflation >= 1.0) {
            return Err(("inflation", self.inflation));
        }
        if !(self.max_rate_hz.is_finite() && self.max_rate_hz >= 0.0) {
            return Err(("max_rate_hz", self.max_rate_hz));
        }
        Ok(())
    }
}

/// The undisturbed field the checks compare against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldReference {
    /// |m_ref|, µT.
    pub magnitude_ut: f64,
    /// Dip (inclination, positive down), rad.
    pub dip_rad: f64,
}

impl FieldReference {
    /// The reference of a body-frame field read at the attitude `attitude`; `None` for a zero or
    /// non-finite field.
    pub fn from_field(field_body: &Vector3<f64>, attitude: &UnitQuaternion<f64>) -> Option<Self> {
        let magnitude_ut = field_body.norm();
        if !(magnitude_ut.is_finite() && magnitude_ut > 0.0) {
            return None;
        }
        Some(Self {
            magnitude_ut,
            dip_rad: dip(&(attitude * field_body)),
        })
    }
}

/// Dip of a navigation-frame field: angle below the horizontal, rad.
pub fn dip(field_ned: &Vector3<f64>) -> f64 {
    field_ned.z.atan2(field_ned.x.hypot(field_ned.y))
}

/// The magnetometer heading `ψ̂ − (α − D)` (rad, wrapped to (−π, π]) for the body field and the
/// filter's attitude; `None` when the horizontal field is too weak to define an azimuth.
pub fn measured_heading(
    field_body: &Vector3<f64>,
    attitude: &UnitQuaternion<f64>,
    declination_rad: f64,
) -> Option<f64> {
    let h = attitude * field_body;
    let horizontal = h.x.hypot(h.y);
    // NaN compares false, so a non-finite field is refused here as well.
    if horizontal.is_nan() || horizontal <= 0.05 * h.norm() {
        return None;
    }
    let c = attitude.to_rotation_matrix();
    let psi = c[(1, 0)].atan2(c[(0, 0)]);
    Some(wrap_pi(psi - (h.y.atan2(h.x) - declination_rad)))
}

/// σ of the heading measurement, rad, after the adaptive checks.
pub fn adaptive_sigma(
    config: &MagAidingConfig,
    reference: &FieldReference,
    specific_force: &Vector3<f64>,
    gravity: f64,
    field_body: &Vector3<f64>,
    attitude: &UnitQuaternion<f64>,
) -> f64 {
    let force = (specific_force.norm() - gravity).abs() / config.specific_force_tolerance_mps2;
    let magnitude = (field_body.norm() - reference.magnitude_ut).abs() / config.field_tolerance_ut;
    let dip_ratio = (dip(&(attitude * field_body)) - reference.dip_rad).abs()
        / config.dip_tolerance_deg.to_radians();
    let r = force.max(magnitude).max(dip_ratio);
    let sigma = config.sigma_deg.to_radians();
    if r <= 1.0 {
        sigma
    } else {
        sigma * config.inflation * r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attitude::quaternion_from_euler;

    /// Earth field of 50 µT, 60° dip, pointing to magnetic north (`declination` east of true).
    fn earth_field(declination: f64) -> Vector3<f64> {
        let (dip, f) = (60f64.to_radians(), 50.0);
        Vector3::new(
            f * dip.cos() * declination.cos(),
            f * dip.cos() * declination.sin(),
            f * dip.sin(),
        )
    }

    #[test]
    fn the_measured_heading_is_the_true_heading_whatever_the_filter_believes() {
        let d = 10f64.to_radians();
        let truth = quaternion_from_euler(0.2, -0.3, 1.0);
        let body = truth.inverse() * earth_field(d);
        // The filter's heading 0.3 rad off, its tilt right: the measurement is the true heading.
        let estimate = quaternion_from_euler(0.2, -0.3, 1.3);
        let psi = measured_heading(&body, &estimate, d).unwrap();
        assert!((psi - 1.0).abs() < 1e-12, "{psi}");
    }

    #[test]
    fn a_vertical_field_defines_no_heading() {
        let body = Vector3::new(0.0, 0.0, 50.0);
        assert_eq!(
            measured_heading(&body, &UnitQuaternion::identity(), 0.0),
            None
        );
    }

    #[test]
    fn sigma_is_the_base_within_tolerance_and_grows_with_the_worst_ratio_beyond() {
        let c = MagAidingConfig::default();
        let q = quaternion_from_euler(0.1, 0.05, 2.0);
        let body = q.inverse() * earth_field(0.0);
        let reference = FieldReference::from_field(&body, &q).unwrap();
        assert!((reference.magnitude_ut - 50.0).abs() < 1e-12);
        assert!((reference.dip_rad - 60f64.to_radians()).abs() < 1e-12);
        let g = 9.81;
        let level_f = q.inverse() * Vector3::new(0.0, 0.0, -g);
        let base = c.sigma_deg.to_radians();
        let s = adaptive_sigma(&c, &reference, &level_f, g, &body, &q);
        assert!((s - base).abs() < 1e-15);
        // |f| 2 m/s² off g: ratio 4 against the 0.5 m/s² tolerance.
        let pushed = level_f * ((g + 2.0) / g);
        let s = adaptive_sigma(&c, &reference, &pushed, g, &body, &q);
        assert!((s - base * c.inflation * 4.0).abs() < 1e-12, "{s}");
        // A field 20 µT stronger: ratio 4 against the 5 µT tolerance, the dip unchanged.
        let disturbed = body * 1.4;
        let s = adaptive_sigma(&c, &reference, &level_f, g, &disturbed, &q);
        assert!((s - base * c.inflation * 4.0).abs() < 1e-12, "{s}");
    }

    #[test]
    fn bad_settings_name_the_field() {
        let mut c = MagAidingConfig::default();
        assert!(c.check().is_ok());
        c.inflation = 0.5;
        assert_eq!(c.check(), Err(("inflation", 0.5)));
        c = MagAidingConfig {
            sigma_deg: f64::NAN,
            ..MagAidingConfig::default()
        };
        assert_eq!(c.check().map_err(|e| e.0), Err("sigma_deg"));
    }
}
