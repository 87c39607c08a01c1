//! Where, and when, the reference measures its position: the antenna's lever arm from the units
//! and the lead of its position over the units' clock, fitted on the other flights.
//!
//! The simulated receiver ([`super::receiver`]) is made from the reference's positions, which are
//! an RTK antenna's: a point some centimetres from the units, on a clock aligned to the units by
//! the reference's *attitude* ([`crate::datasets::quadrotor`]), not by its position. A receiver
//! configured with the wrong lever arm or time tells the filter that the airframe accelerates when
//! it only turns, and the filter turns that into tilt: 0.16 m of arm at 1 rad/s is 0.16 m/s. A
//! user measures the arm on the airframe and the delay on the bench; here both are fitted from the
//! data, on the flights other than the one scored, like the units' mounting.
//!
//! The fit: at each reference row k with neighbours h = 0.1 s either side, the second difference of
//! the reference position is the antenna's acceleration averaged with a triangular kernel of
//! half-width h. The units' specific force, turned to NED by the reference attitude and averaged
//! with the same kernel, gives the units' acceleration `ā`. Their difference is linear in
//! - the lever arm `r` (body frame): the second difference of `C r`;
//! - the position's lead `τ` (the reference position stamped t is the antenna's at t + τ): `τ`
//!   times the jerk of `ā`;
//! - the units' small mounting tilt about x and y and their accelerometer bias, nuisances that
//!   would otherwise leak into the two above.
//!
//! Per flight the normal equations of this least squares are kept; a flight's antenna is solved
//! from the sum over the other flights.

use nalgebra::{Matrix3, SMatrix, SVector, Vector3};
use rins_navigator::attitude::quaternion_from_euler;

use crate::datasets::quadrotor::TruthRow;
use crate::quadrotor_nav::frames::Motion;

/// Unknowns: lever arm (3), lead (1), mounting tilt about x and y (2), accelerometer bias (3).
pub const UNKNOWNS: usize = 9;
/// Standard gravity, m/s²: its departure from the local value is absorbed by the bias terms.
pub(super) const GRAVITY_MPS2: f64 = 9.806_65;
/// Reference row spacing the second difference is taken over, s, and how far it may stray.
const ROW_STEP_S: f64 = 0.1;
const ROW_STEP_TOLERANCE_S: f64 = 0.02;
/// Half-span of the central difference that gives the jerk, s.
const JERK_HALF_SPAN_S: f64 = 0.02;
/// Smallest pivot of the normal matrix's Cholesky factor, relative to its largest diagonal, for
/// a fit to be believed: below it the flights do not excite one of the unknowns.
const MIN_RELATIVE_CONDITION: f64 = 1e-10;

/// One flight's (or a sum of flights') normal equations of the fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalEquations {
    /// XᵀX.
    pub xtx: SMatrix<f64, UNKNOWNS, UNKNOWNS>,
    /// XᵀY.
    pub xty: SVector<f64, UNKNOWNS>,
    /// Reference rows used.
    pub rows: usize,
}

impl Default for NormalEquations {
    fn default() -> Self {
        Self {
            xtx: SMatrix::zeros(),
            xty: SVector::zeros(),
            rows: 0,
        }
    }
}

impl std::ops::AddAssign<&NormalEquations> for NormalEquations {
    fn add_assign(&mut self, other: &NormalEquations) {
        self.xtx += other.xtx;
        self.xty += other.xty;
        self.rows += other.rows;
    }
}

/// Where and when the reference measures position.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Antenna {
    /// From the units to the antenna, body FRD, m.
    pub lever_arm_m: [f64; 3],
    /// The reference position stamped t is the antenna's at t + this, s.
    pub position_lead_s: f64,
}

/// Per IMU row, what the kernel averages: acceleration NED (3), then the mounting regressors
/// `C (e_x × f)` (3) and `C (e_y × f)` (3), then the columns of `C` (9).
pub(super) type Row = [f64; 18];

pub(super) fn unwrapped_headings(truth: &[TruthRow]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::with_capacity(truth.len());
    for r in truth {
        let h = match out.last() {
            Some(&prev) => {
                let d = (r.heading_rad - prev + std::f64::consts::PI)
                    .rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                prev + d
            }
            None => r.heading_rad,
        };
        out.push(h);
    }
    out
}

pub(super) fn attitude(roll: f64, pitch: f64, heading: f64) -> Matrix3<f64> {
    quaternion_from_euler(roll, pitch, heading)
        .to_rotation_matrix()
        .into_inner()
}

/// The reference attitude at `t_s`, interpolated linearly in roll, pitch and unwrapped heading.
pub(super) fn attitude_at(truth: &[TruthRow], headings: &[f64], t_s: f64) -> Option<Matrix3<f64>> {
    let i = truth.partition_point(|r| r.t_s <= t_s);
    if i == 0 || i >= truth.len() {
        return None;
    }
    let (a, b) = (&truth[i - 1], &truth[i]);
    let span = b.t_s - a.t_s;
    if span.is_nan() || span <= 0.0 {
        return None;
    }
    let w = (t_s - a.t_s) / span;
    let lerp = |x: f64, y: f64| x + w * (y - x);
    Some(attitude(
        lerp(a.roll_rad, b.roll_rad),
        lerp(a.pitch_rad, b.pitch_rad),
        lerp(headings[i - 1], headings[i]),
    ))
}

/// Per IMU row, the kernel's inputs, with the units' axes `unit_from_vehicle` turned from the
/// reference's (`C_unit = C_reference · unit_from_vehicle`).
pub(super) fn imu_rows(
    truth: &[TruthRow],
    headings: &[f64],
    motion: &Motion,
    unit_from_vehicle: &Matrix3<f64>,
) -> Vec<Option<Row>> {
    motion
        .samples
        .iter()
        .enumerate()
        .map(|(j, s)| {
            let c = attitude_at(truth, headings, motion.time(j))? * unit_from_vehicle;
            let f = Vector3::from(s.accel_mps2);
            let a = c * f + Vector3::new(0.0, 0.0, GRAVITY_MPS2);
            let tx = c * Vector3::x().cross(&f);
            let ty = c * Vector3::y().cross(&f);
            let mut row = [0.0; 18];
            row[..3].copy_from_slice(a.as_slice());
            row[3..6].copy_from_slice(tx.as_slice());
            row[6..9].copy_from_slice(ty.as_slice());
            for (k, column) in c.column_iter().enumerate() {
                row[9 + 3 * k..12 + 3 * k].copy_from_slice(column.as_slice());
            }
            Some(row)
        })
        .collect()
}

/// Triangular-kernel average of the rows within `half` of `t_s`; `None` when any is missing.
pub(super) fn kernel(rows: &[Option<Row>], motion: &Motion, t_s: f64, half: f64) -> Option<Row> {
    let index = |t: f64| ((t - motion.t0_s) / motion.dt_s).max(0.0);
    let from = index(t_s - half).ceil() as usize;
    let to = (index(t_s + half).floor() as usize).min(rows.len().checked_sub(1)?);
    let (mut sum, mut weights) = ([0.0; 18], 0.0);
    for (j, row) in rows.iter().enumerate().take(to + 1).skip(from) {
        let row = row.as_ref()?;
        let w = half - (motion.time(j) - t_s).abs();
        if w <= 0.0 {
            continue;
        }
        for (s, x) in sum.iter_mut().zip(row) {
            *s += w * x;
        }
        weights += w;
    }
    (weights > 0.0).then(|| sum.map(|s| s / weights))
}

/// One flight's normal equations from its reference and its units' motion (body FRD).
pub fn normal_equations(truth: &[TruthRow], motion: &Motion) -> NormalEquations {
    let headings = unwrapped_headings(truth);
    let rows = imu_rows(truth, &headings, motion, &Matrix3::identity());
    let mut eq = NormalEquations::default();
    for k in 1..truth.len().saturating_sub(1) {
        let (a, b, c) = (&truth[k - 1], &truth[k], &truth[k + 1]);
        let (h1, h2) = (b.t_s - a.t_s, c.t_s - b.t_s);
        if (h1 - h2).abs() > 1e-3 || (h1 - ROW_STEP_S).abs() > ROW_STEP_TOLERANCE_S {
            continue;
        }
        let h = h1;
        let p = |r: &TruthRow| Vector3::new(r.north_m, r.east_m, r.down_m);
        let accel = (p(c) - 2.0 * p(b) + p(a)) / (h * h);
        let cs =
            [k - 1, k, k + 1].map(|m| attitude(truth[m].roll_rad, truth[m].pitch_rad, headings[m]));
        let d2c = (cs[2] - 2.0 * cs[1] + cs[0]) / (h * h);
        let (Some(mid), Some(late), Some(early)) = (
            kernel(&rows, motion, b.t_s, h),
            kernel(&rows, motion, b.t_s + JERK_HALF_SPAN_S, h),
            kernel(&rows, motion, b.t_s - JERK_HALF_SPAN_S, h),
        ) else {
            continue;
        };
        for i in 0..3 {
            let jerk = (late[i] - early[i]) / (2.0 * JERK_HALF_SPAN_S);
            let x = SVector::<f64, UNKNOWNS>::from([
                d2c[(i, 0)],
                d2c[(i, 1)],
                d2c[(i, 2)],
                jerk,
                mid[3 + i],
                mid[6 + i],
                mid[9 + i],
                mid[12 + i],
                mid[15 + i],
            ]);
            let y = accel[i] - mid[i];
            eq.xtx += x * x.transpose();
            eq.xty += x * y;
        }
        eq.rows += 1;
    }
    eq
}

/// The antenna solved from `eq`; `None` when the motion does not tell one of the unknowns.
pub fn solve(eq: &NormalEquations) -> Option<Antenna> {
    let scale = eq.xtx.diagonal().max();
    if scale.is_nan() || scale <= 0.0 {
        return None;
    }
    let chol = eq.xtx.cholesky()?;
    let pivots = chol.l_dirty().diagonal();
    if pivots
        .iter()
        .any(|&d| d.is_nan() || d * d <= MIN_RELATIVE_CONDITION * scale)
    {
        return None;
    }
    let th = chol.solve(&eq.xty);
    th.iter().all(|x| x.is_finite()).then(|| Antenna {
        lever_arm_m: [th[0], th[1], th[2]],
        position_lead_s: th[3],
    })
}

/// For each flight, the antenna fitted on all the others (the nominal zero antenna when they do
/// not tell it, or when there is no other flight).
pub fn held_out(flights: &[NormalEquations]) -> Vec<Antenna> {
    (0..flights.len())
        .map(|f| {
            let mut sum = NormalEquations::default();
            for (g, eq) in flights.iter().enumerate() {
                if g != f {
                    sum += eq;
                }
            }
            solve(&sum).unwrap_or_default()
        })
        .collect()
}

/// The antenna fitted on every flight (in sample), for the report.
pub fn in_sample(flights: &[NormalEquations]) -> Option<Antenna> {
    let mut sum = NormalEquations::default();
    for eq in flights {
        sum += eq;
    }
    solve(&sum)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor_gnss::synthetic;

    fn flight(arm: [f64; 3], lead_s: f64) -> (Vec<TruthRow>, Motion) {
        synthetic::flight(arm, lead_s, |_| 0.0)
    }

    const ARM: [f64; 3] = [-0.06, 0.02, -0.16];
    const LEAD_S: f64 = 0.027;

    #[test]
    fn the_arm_and_lead_of_a_known_flight_are_found() {
        let (truth, motion) = flight(ARM, LEAD_S);
        let eq = normal_equations(&truth, &motion);
        assert!(eq.rows > 550, "{}", eq.rows);
        let a = solve(&eq).expect("a turning flight tells the antenna");
        for (got, want) in a.lever_arm_m.iter().zip(ARM) {
            assert!((got - want).abs() < 0.005, "{:?} vs {ARM:?}", a.lever_arm_m);
        }
        assert!(
            (a.position_lead_s - LEAD_S).abs() < 0.002,
            "{}",
            a.position_lead_s
        );
    }

    #[test]
    fn each_flight_gets_the_others_fit_and_a_still_set_gets_none() {
        let (truth, motion) = flight(ARM, LEAD_S);
        let (other_truth, other_motion) = flight([0.1, 0.0, 0.0], 0.0);
        let flights = [
            normal_equations(&other_truth, &other_motion),
            normal_equations(&truth, &motion),
        ];
        let held = held_out(&flights);
        // Flight 0 is scored with flight 1's antenna, and the other way round.
        assert!((held[0].lever_arm_m[2] - ARM[2]).abs() < 0.005);
        assert!((held[1].lever_arm_m[0] - 0.1).abs() < 0.005);
        assert!(held[1].position_lead_s.abs() < 0.002);
        // Nothing to learn from: the nominal antenna.
        assert_eq!(
            held_out(&[NormalEquations::default()]),
            vec![Antenna::default()]
        );
        assert!(in_sample(&[]).is_none());
    }
}
