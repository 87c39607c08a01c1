//! How well the reference agrees with itself and with the units: a floor under any filter's
//! attitude error scored against it.
//!
//! Two checks per flight, on the fused units' motion and the reference's 10 Hz rows:
//! - **attitude against the gyros**: over each pair of reference rows [`SPAN_S`] apart, the change
//!   of the reference's attitude (turned into the units' axes by their mounting) against the fused
//!   rate integrated over the same span. The north and east components of the rotation between the
//!   two are tilt; each flight's mean (a gyro bias) is removed.
//! - **position against attitude**: the reference's acceleration from its positions (second
//!   differences over ±[`SPAN_S`], the antenna's arm and lead applied) against the units' specific
//!   force turned by the reference's attitude (and mounting) and averaged with the same triangular
//!   kernel. The horizontal misfit over g is tilt; each flight's mean (an accelerometer bias) is
//!   removed.
//!
//! A filter that follows the gyros, or the positions through the accelerometers, cannot agree with
//! an attitude that agrees with neither to better than these over a second.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use serde::Serialize;

use super::antenna::{self, Antenna};
use crate::datasets::quadrotor::TruthRow;
use crate::quadrotor_ahrs::mounting::mounting_rotation;
use crate::quadrotor_nav::frames::Motion;

/// Span of each comparison, s.
pub const SPAN_S: f64 = 1.0;
/// How far a pair of rows may stray from [`SPAN_S`], s.
const SPAN_TOLERANCE_S: f64 = 0.02;

/// One flight's checks, RMS per horizontal axis, degrees of tilt.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct ReferenceCheck {
    /// The reference's attitude change against the integrated gyros.
    pub attitude_vs_gyro_deg: f64,
    /// The reference's position acceleration against its attitude and the accelerometers.
    pub position_vs_attitude_deg: f64,
    /// Spans compared (attitude, position).
    pub spans: [usize; 2],
}

/// RMS per axis of the north/east pairs in `e` after removing their mean, degrees; NaN without any.
fn centred_rms_deg(e: &[[f64; 2]]) -> f64 {
    if e.is_empty() {
        return f64::NAN;
    }
    let n = e.len() as f64;
    let mean = [0, 1].map(|k| e.iter().map(|x| x[k]).sum::<f64>() / n);
    let ss: f64 = e
        .iter()
        .map(|x| (x[0] - mean[0]).powi(2) + (x[1] - mean[1]).powi(2))
        .sum();
    (ss / (2.0 * n)).sqrt().to_degrees()
}

/// The rotation vector of the rotation matrix `m` (by way of a quaternion: exact near identity).
pub(super) fn rotation_vector(m: &Matrix3<f64>) -> Vector3<f64> {
    UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*m)).scaled_axis()
}

/// The row `span_s` after row `a`, when there is one within the tolerance.
fn partner(truth: &[TruthRow], a: usize, span_s: f64) -> Option<usize> {
    let want = truth[a].t_s + span_s;
    let b = truth.partition_point(|r| r.t_s < want - SPAN_TOLERANCE_S);
    truth
        .get(b)
        .filter(|r| (r.t_s - want).abs() <= SPAN_TOLERANCE_S)
        .map(|_| b)
}

/// The fused rate integrated from `from_s` to `to_s` (sample j covers the interval ending at its
/// time); `None` outside the motion.
fn integrated(motion: &Motion, from_s: f64, to_s: f64) -> Option<Rotation3<f64>> {
    let mut r = Rotation3::identity();
    let mut s = from_s;
    while s < to_s - 1e-12 {
        // The first sample whose interval ends after s (rounding can put s just short of a
        // sample's time when it is that time).
        let mut j = usize::try_from(((s - motion.t0_s) / motion.dt_s).floor() as i64 + 1).ok()?;
        while motion.time(j) <= s {
            j += 1;
        }
        let sample = motion.samples.get(j)?;
        let end = motion.time(j).min(to_s);
        r *= Rotation3::new(Vector3::from(sample.gyro_rps) * (end - s));
        s = end;
    }
    Some(r)
}

fn attitude_vs_gyro(
    truth: &[TruthRow],
    motion: &Motion,
    unit_from_vehicle: &Matrix3<f64>,
) -> Vec<[f64; 2]> {
    let headings = antenna::unwrapped_headings(truth);
    let unit = |k: usize| {
        antenna::attitude(truth[k].roll_rad, truth[k].pitch_rad, headings[k]) * unit_from_vehicle
    };
    (0..truth.len())
        .filter_map(|a| {
            let b = partner(truth, a, SPAN_S)?;
            let r = integrated(motion, truth[a].t_s, truth[b].t_s)?;
            let v = rotation_vector(&(unit(b) * (unit(a) * r.matrix()).transpose()));
            Some([v[0], v[1]])
        })
        .collect()
}

fn position_vs_attitude(
    truth: &[TruthRow],
    motion: &Motion,
    unit_from_vehicle: &Matrix3<f64>,
    antenna: &Antenna,
) -> Vec<[f64; 2]> {
    let headings = antenna::unwrapped_headings(truth);
    let rows = antenna::imu_rows(truth, &headings, motion, unit_from_vehicle);
    let arm = Vector3::from(antenna.lever_arm_m);
    let lead = antenna.position_lead_s;
    // The units' position at row m: the antenna's, stamped `lead` early, less the arm.
    let units_at = |m: usize| -> Option<Vector3<f64>> {
        let c = antenna::attitude_at(truth, &headings, truth[m].t_s + lead)? * unit_from_vehicle;
        let r = &truth[m];
        Some(Vector3::new(r.north_m, r.east_m, r.down_m) - c * arm)
    };
    (0..truth.len())
        .filter_map(|a| {
            let k = partner(truth, a, SPAN_S)?;
            let b = partner(truth, k, SPAN_S)?;
            let h = truth[k].t_s - truth[a].t_s;
            if (truth[b].t_s - truth[k].t_s - h).abs() > 1e-3 {
                return None;
            }
            let accel = (units_at(b)? - 2.0 * units_at(k)? + units_at(a)?) / (h * h);
            let kernel = antenna::kernel(&rows, motion, truth[k].t_s + lead, h)?;
            Some([0, 1].map(|i| (accel[i] - kernel[i]) / antenna::GRAVITY_MPS2))
        })
        .collect()
}

/// The two checks of one flight: `tilt_rad` the units' mounting, `antenna` the reference's.
pub fn check(
    truth: &[TruthRow],
    motion: &Motion,
    tilt_rad: [f64; 2],
    antenna: &Antenna,
) -> ReferenceCheck {
    // C_unit = C_vehicle · mounting⁻¹.
    let unit_from_vehicle = mounting_rotation(tilt_rad)
        .inverse()
        .to_rotation_matrix()
        .into_inner();
    let attitude = attitude_vs_gyro(truth, motion, &unit_from_vehicle);
    let position = position_vs_attitude(truth, motion, &unit_from_vehicle, antenna);
    ReferenceCheck {
        attitude_vs_gyro_deg: centred_rms_deg(&attitude),
        position_vs_attitude_deg: centred_rms_deg(&position),
        spans: [attitude.len(), position.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor_gnss::synthetic::flight;

    const ARM: [f64; 3] = [-0.06, 0.02, -0.16];

    #[test]
    fn a_consistent_reference_passes_and_a_wobbling_one_does_not() {
        let antenna = Antenna {
            lever_arm_m: ARM,
            position_lead_s: 0.027,
        };
        let (truth, motion) = flight(ARM, 0.027, |_| 0.0);
        let c = check(&truth, &motion, [0.0; 2], &antenna);
        assert!(c.spans[0] > 500 && c.spans[1] > 500, "{c:?}");
        assert!(c.attitude_vs_gyro_deg < 0.01, "{c:?}");
        assert!(c.position_vs_attitude_deg < 0.05, "{c:?}");
        // A reference roll that wobbles by 0.5° at 0.3 Hz against what the units and the
        // positions say: both checks see about that much.
        let wobble = |t: f64| 0.5_f64.to_radians() * (std::f64::consts::TAU * 0.3 * t).sin();
        let (truth, motion) = flight(ARM, 0.027, wobble);
        let c = check(&truth, &motion, [0.0; 2], &antenna);
        assert!((0.25..0.55).contains(&c.attitude_vs_gyro_deg), "{c:?}");
        assert!((0.1..0.4).contains(&c.position_vs_attitude_deg), "{c:?}");
    }
}
