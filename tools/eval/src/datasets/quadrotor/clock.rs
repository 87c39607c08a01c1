//! The ground truth's clock, found from the body rates.
//!
//! The truth (10 Hz) runs on its own clock, up to about a second off the units'. Its attitude
//! gives body rates: central differences of the ZYX Euler angles (roll, pitch, compass heading
//! unwrapped) turned into FRD rates by [`body_rate_from_euler_rates`]. A central difference over
//! rows k − 1 and k + 1 is the mean rate over that span, so it is compared with the reference
//! unit's gyro averaged over the same span, read off the gyro's running integral. The reference
//! unit sits within a few degrees of the airframe's axes, so the rates are compared axis by axis
//! without a rotation. The offset is the one that minimises the spread of the differences (a
//! constant difference is a gyro bias and is allowed): searched on a grid, then refined by a
//! parabola through the best three grid points.
//!
//! The gyro is the unit's measurement, not its on-board attitude filter, whose output may lag
//! the motion by its own filter delay; that delay would otherwise be read as a clock offset.

use super::TruthRow;
use super::align::interpolate_uniform;
use super::frame::body_rate_from_euler_rates;

/// Largest truth clock offset searched, s.
pub const MAX_TRUTH_OFFSET_S: f64 = 1.5;
/// Spacing of the search grid before refinement, s (one 120 Hz period).
pub const GRID_S: f64 = 1.0 / 120.0;
/// Longest truth row spacing a central difference is taken over, s (3 rows of 10 Hz): across a
/// longer gap the difference is no longer a rate at one instant.
const MAX_DIFFERENCE_SPAN_S: f64 = 0.3;
/// Smallest variance of the truth's body rate, summed over the axes, for the offset to be
/// observable, (rad/s)² ((1 °/s)²): a vehicle that does not turn gives no timing information.
const MIN_RATE_VARIANCE: f64 = 3.05e-4;

/// The truth's mean body rate over one span of its own clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthRate {
    /// Start of the span (row k − 1), truth file time, s.
    pub from_s: f64,
    /// End of the span (row k + 1), truth file time, s.
    pub to_s: f64,
    /// Mean body rate over the span, FRD, rad/s.
    pub rate_rps: [f64; 3],
}

/// The body rates of the truth rows: one per interior row whose neighbours are close enough.
pub fn truth_body_rates(truth: &[TruthRow]) -> Vec<TruthRate> {
    let heading = unwrap(&truth.iter().map(|r| r.heading_rad).collect::<Vec<_>>());
    (1..truth.len().saturating_sub(1))
        .filter_map(|k| {
            let (a, b) = (&truth[k - 1], &truth[k + 1]);
            let span = b.t_s - a.t_s;
            if !(span > 0.0 && span <= MAX_DIFFERENCE_SPAN_S) {
                return None;
            }
            let rates = [
                (b.roll_rad - a.roll_rad) / span,
                (b.pitch_rad - a.pitch_rad) / span,
                (heading[k + 1] - heading[k - 1]) / span,
            ];
            let euler = [truth[k].roll_rad, truth[k].pitch_rad, heading[k]];
            Some(TruthRate {
                from_s: a.t_s,
                to_s: b.t_s,
                rate_rps: body_rate_from_euler_rates(euler, rates),
            })
        })
        .collect()
}

/// `angles` with the jumps of more than π between neighbours taken out.
fn unwrap(angles: &[f64]) -> Vec<f64> {
    let mut offset = 0.0;
    let mut out: Vec<f64> = Vec::with_capacity(angles.len());
    for (k, &a) in angles.iter().enumerate() {
        if k > 0 {
            let d = a - angles[k - 1];
            offset -= std::f64::consts::TAU * (d / std::f64::consts::TAU).round();
        }
        out.push(a + offset);
    }
    out
}

/// Mean and variance accumulator.
#[derive(Default)]
struct Spread {
    n: f64,
    sum: f64,
    sum_sq: f64,
}

impl Spread {
    fn push(&mut self, x: f64) {
        self.n += 1.0;
        self.sum += x;
        self.sum_sq += x * x;
    }

    fn variance(&self) -> f64 {
        (self.sum_sq - self.sum * self.sum / self.n) / self.n
    }
}

/// The offset δ (s) such that truth file time t is the gyro's time t + δ: `gyro` is the
/// reference unit's FRD rate, uniform from `t0` with period `dt`. Searched over
/// ±`max_offset_s` on a grid of `step_s`, then refined. `None` when the truth hardly turns,
/// when the series overlap on less than half of the truth's rates, or when the best fit lies at
/// the edge of the search.
pub fn estimate_truth_offset(
    truth: &[TruthRate],
    gyro: &[[f64; 3]],
    t0: f64,
    dt: f64,
    max_offset_s: f64,
    step_s: f64,
) -> Option<f64> {
    let mut motion: [Spread; 3] = Default::default();
    for r in truth {
        for (s, x) in motion.iter_mut().zip(r.rate_rps) {
            s.push(x);
        }
    }
    if truth.len() < 3 || motion.iter().map(Spread::variance).sum::<f64>() < MIN_RATE_VARIANCE {
        return None;
    }
    let integral = running_integral(gyro, dt);
    let steps = (max_offset_s / step_s).round() as i64;
    let costs: Vec<Option<f64>> = (-steps..=steps)
        .map(|k| cost(truth, &integral, t0, dt, k as f64 * step_s))
        .collect();
    let (best, c0) = costs
        .iter()
        .enumerate()
        .filter_map(|(i, c)| c.map(|c| (i, c)))
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let (Some(Some(cm)), Some(Some(cp))) = (
        best.checked_sub(1).map(|i| costs[i]),
        costs.get(best + 1).copied(),
    ) else {
        return None;
    };
    // Vertex of the parabola through the best grid point and its neighbours.
    let curvature = cm - 2.0 * c0 + cp;
    let shift = if curvature > 0.0 {
        (0.5 * (cm - cp) / curvature).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    Some(((best as i64 - steps) as f64 + shift) * step_s)
}

/// The running integral of each gyro axis (trapezoids), row j at time t0 + j·dt.
fn running_integral(gyro: &[[f64; 3]], dt: f64) -> [Vec<f64>; 3] {
    std::array::from_fn(|axis| {
        let mut sum = 0.0;
        let mut out = Vec::with_capacity(gyro.len());
        for (j, g) in gyro.iter().enumerate() {
            if j > 0 {
                sum += 0.5 * (gyro[j - 1][axis] + g[axis]) * dt;
            }
            out.push(sum);
        }
        out
    })
}

/// Summed variance over the axes of (truth rate − gyro mean over the same span) at offset
/// `offset`; `None` when fewer than half of the truth's rates fall inside the gyro record.
fn cost(
    truth: &[TruthRate],
    integral: &[Vec<f64>; 3],
    t0: f64,
    dt: f64,
    offset: f64,
) -> Option<f64> {
    let mut residual: [Spread; 3] = Default::default();
    for r in truth {
        let (a, b) = (r.from_s + offset, r.to_s + offset);
        for (axis, spread) in residual.iter_mut().enumerate() {
            let at = |t| interpolate_uniform(&integral[axis], t0, dt, t);
            let (Some(ia), Some(ib)) = (at(a), at(b)) else {
                break;
            };
            spread.push(r.rate_rps[axis] - (ib - ia) / (b - a));
        }
    }
    let n = residual[0].n;
    (n >= 2.0 && n >= 0.5 * truth.len() as f64).then(|| residual.iter().map(Spread::variance).sum())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A vehicle rocking in roll and pitch while it turns through several whole turns: ZYX
    /// Euler angles and their rates.
    fn motion(t: f64) -> ([f64; 3], [f64; 3]) {
        let (a, w1, b, w2, r, c, w3) = (0.35, 1.7, 0.25, 1.1, 0.6, 0.8, 0.9);
        (
            [
                a * (w1 * t).sin(),
                b * (w2 * t + 0.4).sin(),
                r * t + c * (w3 * t).sin(),
            ],
            [
                a * w1 * (w1 * t).cos(),
                b * w2 * (w2 * t + 0.4).cos(),
                r + c * w3 * (w3 * t).cos(),
            ],
        )
    }

    fn truth_row(t: f64, euler: [f64; 3]) -> TruthRow {
        TruthRow {
            t_s: t,
            distance_m: 0.0,
            speed_mps: 0.0,
            // A compass heading: wrapped to [0, 2π).
            heading_rad: euler[2].rem_euclid(std::f64::consts::TAU),
            pitch_rad: euler[1],
            roll_rad: euler[0],
            height_m: 0.0,
            north_m: 0.0,
            east_m: 0.0,
            down_m: 0.0,
        }
    }

    /// The unit's gyro at 120 Hz from t = 0 for 60 s, and the truth at 10 Hz on a clock such
    /// that truth file time t shows the motion of gyro time t + `offset`.
    fn pair(offset: f64) -> (Vec<[f64; 3]>, Vec<TruthRow>) {
        let gyro = (0..7200)
            .map(|j| {
                let (e, r) = motion(j as f64 / 120.0);
                body_rate_from_euler_rates(e, r)
            })
            .collect();
        let truth = (0..600)
            .map(|k| {
                let t = k as f64 * 0.1;
                truth_row(t, motion(t + offset).0)
            })
            .collect();
        (gyro, truth)
    }

    #[test]
    fn recovers_a_known_offset_within_5_ms() {
        for offset in [0.437, -0.21, 0.0, 1.2] {
            let (gyro, truth) = pair(offset);
            let rates = truth_body_rates(&truth);
            assert_eq!(rates.len(), 598);
            let got = estimate_truth_offset(&rates, &gyro, 0.0, 1.0 / 120.0, 1.5, GRID_S)
                .unwrap_or(f64::NAN);
            assert!((got - offset).abs() < 0.005, "{offset}: {got}");
        }
    }

    #[test]
    fn truth_rates_match_the_motion() {
        // A central difference over ±h misses h²/6 of the third derivative: here at most
        // 0.35 · 1.7³ ≈ 1.7 rad/s³, so 3e-3 rad/s per angle at h = 0.1 s; the body-rate map
        // mixes three of them, so 0.014 rad/s (1 % of the peak rate, ≈ 1.4 rad/s) bounds it.
        let (_, truth) = pair(0.0);
        for r in truth_body_rates(&truth) {
            let t = 0.5 * (r.from_s + r.to_s);
            let (e, d) = motion(t);
            let expected = body_rate_from_euler_rates(e, d);
            for (got, want) in r.rate_rps.iter().zip(expected) {
                assert!((got - want).abs() < 0.014, "{t}: {r:?}");
            }
        }
    }

    #[test]
    fn a_still_vehicle_or_no_overlap_is_not_estimable() {
        let level: Vec<TruthRow> = (0..100)
            .map(|k| truth_row(k as f64 * 0.1, [0.0; 3]))
            .collect();
        let gyro = vec![[0.0; 3]; 1200];
        let rates = truth_body_rates(&level);
        assert_eq!(
            estimate_truth_offset(&rates, &gyro, 0.0, 1.0 / 120.0, 1.5, GRID_S),
            None
        );
        let (gyro, truth) = pair(0.3);
        let rates = truth_body_rates(&truth);
        // The gyro record starts 100 s after the truth's: no overlap at any offset.
        assert_eq!(
            estimate_truth_offset(&rates, &gyro, 100.0, 1.0 / 120.0, 1.5, GRID_S),
            None
        );
    }
}
