//! Roll and pitch of an attitude solution against the reference, and the fixed mounting tilt
//! between the unit's axes and the airframe's, fitted on other flights.
//!
//! A unit sits on the airframe tilted by a fraction of a degree to a few degrees. Whatever
//! estimates the unit's attitude (rins, or the unit's own on-board filter) estimates the unit's
//! axes, so before it is compared with the airframe's reference attitude it is turned by the
//! mounting rotation `M` (`C_nav←vehicle = C_nav←unit · M`). `M` is a tilt (rotations about the
//! unit's x and y axes; a rotation about z changes roll and pitch only at second order) fitted by
//! Gauss–Newton to minimise the roll/pitch errors of the flights it is given — never the flight
//! being scored.

use nalgebra::{Matrix2, UnitQuaternion, Vector2, Vector3};
use rins_navigator::attitude::{euler_from_quaternion, wrap_pi};

/// A solution's attitude at each reference row of one flight, with the reference's roll and pitch.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Paired {
    /// Time of each row since the start of the run, s.
    pub since_start_s: Vec<f64>,
    /// The solution's body → NED attitude at each reference time.
    pub estimate: Vec<UnitQuaternion<f64>>,
    /// Reference roll at the same times, rad.
    pub roll_rad: Vec<f64>,
    /// Reference pitch at the same times, rad.
    pub pitch_rad: Vec<f64>,
}

impl Paired {
    /// Adds one row.
    pub fn push(
        &mut self,
        since_start_s: f64,
        estimate: UnitQuaternion<f64>,
        roll_rad: f64,
        pitch_rad: f64,
    ) {
        self.since_start_s.push(since_start_s);
        self.estimate.push(estimate);
        self.roll_rad.push(roll_rad);
        self.pitch_rad.push(pitch_rad);
    }

    /// Rows held.
    pub fn len(&self) -> usize {
        self.estimate.len()
    }

    /// True when no row is held.
    pub fn is_empty(&self) -> bool {
        self.estimate.is_empty()
    }
}

/// The mounting tilt as a rotation: `[x, y]` rotation-vector components, rad.
pub fn mounting_rotation(tilt_rad: [f64; 2]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_scaled_axis(Vector3::new(tilt_rad[0], tilt_rad[1], 0.0))
}

/// Roll and pitch errors of row `k` with the mounting `m` applied, rad.
fn errors(p: &Paired, k: usize, m: &UnitQuaternion<f64>) -> [f64; 2] {
    let [roll, pitch, _] = euler_from_quaternion(&(p.estimate[k] * m));
    [
        wrap_pi(roll - p.roll_rad[k]),
        wrap_pi(pitch - p.pitch_rad[k]),
    ]
}

/// The tilt error of row `k` with mounting tilt `tilt_rad`: roll and pitch errors together,
/// `sqrt(e_roll² + e_pitch²)`, rad.
pub fn tilt_error_rad(p: &Paired, k: usize, tilt_rad: [f64; 2]) -> f64 {
    let [r, q] = errors(p, k, &mounting_rotation(tilt_rad));
    r.hypot(q)
}

/// Root mean square of the roll and pitch errors pooled, `sqrt(mean((e_roll² + e_pitch²) / 2))`,
/// degrees, with mounting tilt `tilt_rad`, over the rows at least `from_s` after the run's start;
/// NaN without such rows.
pub fn roll_pitch_rmse_deg(p: &Paired, tilt_rad: [f64; 2], from_s: f64) -> f64 {
    roll_pitch_rmse_between_deg(p, tilt_rad, from_s, f64::INFINITY)
}

/// [`roll_pitch_rmse_deg`] over the rows from `from_s` (included) to `to_s` (excluded) after the
/// run's start; NaN without such rows.
pub fn roll_pitch_rmse_between_deg(p: &Paired, tilt_rad: [f64; 2], from_s: f64, to_s: f64) -> f64 {
    let m = mounting_rotation(tilt_rad);
    let (sum, n) = (0..p.len())
        .filter(|&k| p.since_start_s[k] >= from_s && p.since_start_s[k] < to_s)
        .map(|k| {
            let [r, q] = errors(p, k, &m);
            (r * r + q * q) / 2.0
        })
        .fold((0.0, 0usize), |(s, n), e| (s + e, n + 1));
    if n == 0 {
        return f64::NAN;
    }
    (sum / n as f64).sqrt().to_degrees()
}

/// The mounting tilt minimising the roll/pitch errors of every row of `flights` at least
/// `settle_s` after its run's start (a run started from the airframe's attitude needs a while to
/// find the unit's), by Gauss–Newton from zero with a numerical Jacobian; zero when there are no
/// rows or the fit does not settle on a finite value.
pub fn fit_mounting(flights: &[&Paired], settle_s: f64) -> [f64; 2] {
    const STEP: f64 = 1e-6;
    const ITERATIONS: usize = 8;
    let mut x = Vector2::zeros();
    for _ in 0..ITERATIONS {
        let (mut jtj, mut jte) = (Matrix2::zeros(), Vector2::zeros());
        let m0 = mounting_rotation([x[0], x[1]]);
        let mx = mounting_rotation([x[0] + STEP, x[1]]);
        let my = mounting_rotation([x[0], x[1] + STEP]);
        for p in flights {
            for k in (0..p.len()).filter(|&k| p.since_start_s[k] >= settle_s) {
                let e0 = Vector2::from(errors(p, k, &m0));
                let dx = (Vector2::from(errors(p, k, &mx)) - e0) / STEP;
                let dy = (Vector2::from(errors(p, k, &my)) - e0) / STEP;
                let j = Matrix2::from_columns(&[dx, dy]);
                jtj += j.transpose() * j;
                jte += j.transpose() * e0;
            }
        }
        let Some(step) = jtj.try_inverse().map(|inv| inv * jte) else {
            break;
        };
        x -= step;
        if step.norm() < 1e-10 {
            break;
        }
    }
    if x.iter().all(|v| v.is_finite()) {
        [x[0], x[1]]
    } else {
        [0.0; 2]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_navigator::attitude::quaternion_from_euler;

    /// A vehicle rocking ±25° in roll and pitch and turning through every heading, seen by a
    /// unit mounted with tilt `tilt`: the unit's attitude is `C_vehicle · Mᵀ`.
    fn flight(tilt: [f64; 2], phase: f64) -> Paired {
        let m = mounting_rotation(tilt);
        let mut p = Paired::default();
        for k in 0..400 {
            let t = k as f64 * 0.1 + phase;
            let (roll, pitch, yaw) = (0.45 * (1.3 * t).sin(), 0.4 * (0.7 * t).cos(), 0.2 * t);
            let vehicle = quaternion_from_euler(roll, pitch, yaw);
            p.push(k as f64 * 0.1, vehicle * m.inverse(), roll, pitch);
        }
        p
    }

    #[test]
    fn recovers_the_mounting_of_other_flights_and_scores_zero_with_it() {
        let tilt = [1.5_f64.to_radians(), -2.2_f64.to_radians()];
        let (a, b) = (flight(tilt, 0.0), flight(tilt, 17.0));
        let fitted = fit_mounting(&[&a, &b], 5.0);
        assert!((fitted[0] - tilt[0]).abs() < 1e-9, "{fitted:?}");
        assert!((fitted[1] - tilt[1]).abs() < 1e-9, "{fitted:?}");
        let held_out = flight(tilt, 40.0);
        assert!(roll_pitch_rmse_deg(&held_out, fitted, 0.0) < 1e-6);
        // Without it the errors are of the size of the tilt: between the smaller and the larger
        // component (the rocking mixes them).
        let raw = roll_pitch_rmse_deg(&held_out, [0.0; 2], 0.0);
        assert!(raw > 1.2 && raw < 2.3, "{raw}");
    }

    #[test]
    fn nothing_to_fit_gives_no_tilt_and_no_score() {
        assert_eq!(fit_mounting(&[], 0.0), [0.0; 2]);
        assert!(roll_pitch_rmse_deg(&Paired::default(), [0.0; 2], 0.0).is_nan());
        // Rows before `from_s` do not count.
        let p = flight([0.01, 0.0], 0.0);
        assert!(roll_pitch_rmse_deg(&p, [0.0; 2], 1e9).is_nan());
    }
}
