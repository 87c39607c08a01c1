//! Navigation error against simulator truth: attitude angle and altitude, RMS and maximum, and the
//! horizontal track (distance travelled, end-point error).

use nalgebra::{Quaternion, UnitQuaternion};

use crate::error_stats::ErrorStats;
use crate::horizontal::{HorizontalTrack, Position};

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
    /// Attitude error of the samples whose integrity said ok, degrees: what a user trusting the
    /// integrity could have been misled by.
    pub attitude_deg_while_ok: ErrorStats,
    /// Horizontal position error of the samples whose integrity said ok, m.
    pub horizontal_m_while_ok: ErrorStats,
}

/// One navigation sample with the simulator's truth of its frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScoredSample {
    /// Truth attitude quaternion [w, x, y, z].
    pub truth_q: [f64; 4],
    /// Navigation attitude quaternion [w, x, y, z].
    pub nav_q: [f64; 4],
    /// Truth position.
    pub truth: Position,
    /// Navigation position.
    pub nav: Position,
    /// The navigator's integrity of this sample was ok.
    pub integrity_ok: bool,
    /// The navigator claims a horizontal position (without an initial position, none until the
    /// first absolute fix: its latitude and longitude are placeholders, not an error to score).
    pub position_known: bool,
}

impl Accuracy {
    /// Compares one navigation sample with the simulator's truth.
    pub fn push(&mut self, s: &ScoredSample) {
        let attitude = attitude_error_deg(s.truth_q, s.nav_q);
        self.attitude_deg.push(attitude);
        self.altitude_m.push(s.nav.height_m - s.truth.height_m);
        if s.position_known {
            self.horizontal.push(s.truth, s.nav);
        }
        if s.integrity_ok {
            self.attitude_deg_while_ok.push(attitude);
            if s.position_known {
                self.horizontal_m_while_ok.push(s.truth.distance_to(&s.nav));
            }
        }
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
    fn errors_while_ok_count_only_the_samples_the_integrity_called_ok() {
        let level = [1.0, 0.0, 0.0, 0.0];
        let tilted = UnitQuaternion::from_euler_angles(2f64.to_radians(), 0.0, 0.0);
        let at = |lat_rad| Position {
            lat_rad,
            lon_rad: 0.0,
            height_m: 0.0,
        };
        let mut acc = Accuracy::default();
        // 2° and ~64 m off while degraded, 0.5° and no position error while ok.
        acc.push(&ScoredSample {
            truth_q: level,
            nav_q: [tilted.w, tilted.i, tilted.j, tilted.k],
            truth: at(0.0),
            nav: at(1e-5),
            integrity_ok: false,
            position_known: true,
        });
        let small = UnitQuaternion::from_euler_angles(0.0, 0.5f64.to_radians(), 0.0);
        acc.push(&ScoredSample {
            truth_q: level,
            nav_q: [small.w, small.i, small.j, small.k],
            truth: at(0.0),
            nav: at(0.0),
            integrity_ok: true,
            position_known: true,
        });
        assert!((acc.attitude_deg.max().unwrap() - 2.0).abs() < 1e-9);
        assert!((acc.attitude_deg_while_ok.max().unwrap() - 0.5).abs() < 1e-9);
        assert!(acc.horizontal.errors().max().unwrap() > 60.0);
        assert_eq!(acc.horizontal_m_while_ok.max(), Some(0.0));
        assert_eq!(acc.attitude_deg_while_ok.count(), 1);
    }

    #[test]
    fn a_position_the_navigator_does_not_claim_is_not_scored() {
        let level = [1.0, 0.0, 0.0, 0.0];
        let at = |lat_rad| Position {
            lat_rad,
            lon_rad: 0.0,
            height_m: 0.0,
        };
        let mut acc = Accuracy::default();
        // A placeholder position 5000 km away before the first fix, then 1 m off.
        for (nav, position_known) in [(at(0.8), false), (at(1.0 / 6.4e6), true)] {
            acc.push(&ScoredSample {
                truth_q: level,
                nav_q: level,
                truth: at(0.0),
                nav,
                integrity_ok: true,
                position_known,
            });
        }
        assert!(acc.horizontal.errors().max().unwrap() < 1.1);
        assert!(acc.horizontal_m_while_ok.max().unwrap() < 1.1);
        assert_eq!(acc.attitude_deg.count(), 2);
    }
}
