//! Navigation error against simulator truth: attitude angle and altitude, RMS and maximum, and the
//! horizontal track (distance travelled, end-point error).

use nalgebra::{Quaternion, UnitQuaternion};

use crate::horizontal::HorizontalTrack;

/// RMS and largest of a stream of errors.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ErrorStats {
    n: u64,
    sum_sq: f64,
    max: f64,
}

impl ErrorStats {
    /// Adds one error sample.
    pub fn push(&mut self, error: f64) {
        self.n += 1;
        self.sum_sq += error * error;
        self.max = self.max.max(error.abs());
    }

    /// Samples added so far.
    pub fn count(&self) -> u64 {
        self.n
    }

    /// Root mean square; `None` before the first sample.
    pub fn rms(&self) -> Option<f64> {
        (self.n > 0).then(|| (self.sum_sq / self.n as f64).sqrt())
    }

    /// The largest error, once there is a sample.
    pub fn max(&self) -> Option<f64> {
        (self.n > 0).then_some(self.max)
    }
}

/// Angle in degrees of the rotation between two attitudes given as [w, x, y, z].
pub fn attitude_error_deg(truth: [f64; 4], estimate: [f64; 4]) -> f64 {
    let t =
        UnitQuaternion::from_quaternion(Quaternion::new(truth[0], truth[1], truth[2], truth[3]));
    let e = UnitQuaternion::from_quaternion(Quaternion::new(
        estimate[0],
        estimate[1],
        estimate[2],
        estimate[3],
    ));
    t.angle_to(&e).to_degrees()
}

/// Attitude and altitude error accumulated over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Accuracy {
    /// Attitude error, degrees.
    pub attitude_deg: ErrorStats,
    /// Altitude error, m.
    pub altitude_m: ErrorStats,
    /// Distance the truth travelled over the ground and the solution's horizontal error.
    pub horizontal: HorizontalTrack,
}

impl Accuracy {
    /// Compares one navigation sample (attitude quaternion, altitude) with the simulator's truth.
    pub fn push(&mut self, truth_q: [f64; 4], truth_alt: f64, nav_q: [f64; 4], nav_alt: f64) {
        self.attitude_deg.push(attitude_error_deg(truth_q, nav_q));
        self.altitude_m.push(nav_alt - truth_alt);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn attitude_error_is_the_rotation_angle_between() {
        let a = UnitQuaternion::from_euler_angles(0.1, -0.2, 1.0);
        let delta = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 0.5f64.to_radians());
        let b = a * delta;
        let q = |u: UnitQuaternion<f64>| [u.w, u.i, u.j, u.k];
        assert!((attitude_error_deg(q(a), q(b)) - 0.5).abs() < 1e-9);
        // q and -q are the same attitude.
        let neg = [-b.w, -b.i, -b.j, -b.k];
        assert!((attitude_error_deg(q(a), neg) - 0.5).abs() < 1e-9);
    }

    #[test]
    fn rms_and_max() {
        let mut s = ErrorStats::default();
        assert_eq!(s.rms(), None);
        for e in [3.0, -4.0] {
            s.push(e);
        }
        assert!((s.rms().unwrap() - (12.5f64).sqrt()).abs() < 1e-12);
        assert_eq!(s.max(), Some(4.0));
    }
}
