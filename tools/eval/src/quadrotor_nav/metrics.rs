//! Accuracy figures of one run against the truth: roll/pitch RMSE and height error.

use rins_navigator::attitude::wrap_pi;
use serde::Serialize;

use super::run::Trace;
use crate::datasets::quadrotor::TruthRow;

/// Difference of two angles, wrapped to (−π, π]: 179° against −179° is 2° off, not 358°.
pub fn angle_error(estimate_rad: f64, truth_rad: f64) -> f64 {
    wrap_pi(estimate_rad - truth_rad)
}

/// Root mean square; NaN when empty.
pub fn rms(values: &[f64]) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    (values.iter().map(|x| x * x).sum::<f64>() / values.len() as f64).sqrt()
}

/// Median (mean of the two middle values for an even count); NaN when empty or when any value
/// is NaN (a failed run must not disappear from a summary).
pub fn median(values: &[f64]) -> f64 {
    if values.is_empty() || values.iter().any(|x| x.is_nan()) {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let mid = v.len() / 2;
    if v.len() % 2 == 1 {
        v[mid]
    } else {
        0.5 * (v[mid - 1] + v[mid])
    }
}

/// Mean; NaN when empty.
pub fn mean(values: &[f64]) -> f64 {
    if values.is_empty() {
        f64::NAN
    } else {
        values.iter().sum::<f64>() / values.len() as f64
    }
}

/// Largest value; NaN when empty or when any value is NaN.
pub fn max(values: &[f64]) -> f64 {
    values
        .iter()
        .copied()
        .reduce(|a, b| {
            if a.is_nan() || b.is_nan() {
                f64::NAN
            } else {
                a.max(b)
            }
        })
        .unwrap_or(f64::NAN)
}

/// The trace at time `t_s` by linear interpolation, angles along the short way round:
/// `[roll, pitch, height]`. `None` outside the trace.
pub fn trace_at(trace: &Trace, t_s: f64) -> Option<[f64; 3]> {
    let n = trace.t_s.len();
    let (first, last) = (*trace.t_s.first()?, *trace.t_s.last()?);
    if !(t_s >= first && t_s <= last) {
        return None;
    }
    let i = trace.t_s.partition_point(|&t| t <= t_s).clamp(1, n) - 1;
    let j = (i + 1).min(n - 1);
    let span = trace.t_s[j] - trace.t_s[i];
    let f = if span > 0.0 {
        (t_s - trace.t_s[i]) / span
    } else {
        0.0
    };
    let angle = |v: &[f64]| wrap_pi(v[i] + f * wrap_pi(v[j] - v[i]));
    Some([
        angle(&trace.roll_rad),
        angle(&trace.pitch_rad),
        trace.height_m[i] + f * (trace.height_m[j] - trace.height_m[i]),
    ])
}

/// How one run did against the truth.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scores {
    /// IMU file number; absent for the fused solution.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub imu: Option<usize>,
    /// RMS of the roll error against the truth, degrees.
    pub roll_rmse_deg: f64,
    /// RMS of the pitch error against the truth, degrees.
    pub pitch_rmse_deg: f64,
    /// RMS of roll and pitch errors pooled: `sqrt(mean((e_roll² + e_pitch²) / 2))`.
    pub roll_pitch_rmse_deg: f64,
    /// Height error at the last truth row, m (navigator − truth).
    pub height_error_m: f64,
    /// Largest |height error| over the flight, m.
    pub height_error_max_m: f64,
    /// Truth rows compared.
    pub rows: usize,
    /// Samples the filter did not apply.
    pub skipped_samples: usize,
}

/// Scores the trace against every truth row after t0 (`start_row`) that it covers. Truth rows
/// are compared at their own times (10 Hz); the trace is interpolated to them.
pub fn score(imu: Option<usize>, trace: &Trace, truth: &[TruthRow], start_row: usize) -> Scores {
    let (mut roll, mut pitch, mut height) = (Vec::new(), Vec::new(), Vec::new());
    for row in truth.iter().skip(start_row + 1) {
        let Some([r, p, h]) = trace_at(trace, row.t_s) else {
            continue;
        };
        roll.push(angle_error(r, row.roll_rad));
        pitch.push(angle_error(p, row.pitch_rad));
        height.push(h - row.height_m);
    }
    let pooled: Vec<f64> = roll.iter().chain(&pitch).copied().collect();
    Scores {
        imu,
        roll_rmse_deg: rms(&roll).to_degrees(),
        pitch_rmse_deg: rms(&pitch).to_degrees(),
        roll_pitch_rmse_deg: rms(&pooled).to_degrees(),
        height_error_m: height.last().copied().unwrap_or(f64::NAN),
        height_error_max_m: max(&height.iter().map(|h| h.abs()).collect::<Vec<_>>()),
        rows: roll.len(),
        skipped_samples: trace.skipped,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn angle_errors_wrap_the_short_way() {
        let d = 1.0_f64.to_radians();
        assert!(
            (angle_error(179.0_f64.to_radians(), -179.0_f64.to_radians()) + 2.0 * d).abs() < 1e-12
        );
        assert!(
            (angle_error(-179.0_f64.to_radians(), 179.0_f64.to_radians()) - 2.0 * d).abs() < 1e-12
        );
        assert!((angle_error(3.0 * PI, 0.0) - PI).abs() < 1e-12);
        assert_eq!(angle_error(0.25, 0.25), 0.0);
    }

    #[test]
    fn rms_of_a_hand_example() {
        // (3² + 4² + 0² + 0²) / 4 = 25 / 4.
        assert_eq!(rms(&[3.0, -4.0, 0.0, 0.0]), 2.5);
        assert!(rms(&[]).is_nan());
    }

    #[test]
    fn median_and_max_of_odd_even_and_nan() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), 2.5);
        assert!(median(&[1.0, f64::NAN]).is_nan());
        assert!(median(&[]).is_nan());
        assert_eq!(max(&[1.0, -3.0, 2.0]), 2.0);
        assert!(max(&[1.0, f64::NAN, 2.0]).is_nan());
        assert!(max(&[]).is_nan());
    }

    fn trace(t: &[f64], roll: &[f64], height: &[f64]) -> Trace {
        Trace {
            t_s: t.to_vec(),
            roll_rad: roll.to_vec(),
            pitch_rad: vec![0.0; t.len()],
            height_m: height.to_vec(),
            skipped: 0,
        }
    }

    #[test]
    fn interpolation_crosses_the_wrap_the_short_way() {
        let tr = trace(&[0.0, 1.0], &[PI - 0.1, -PI + 0.1], &[0.0, 2.0]);
        let [r, _, h] = trace_at(&tr, 0.5).unwrap();
        assert!((r.abs() - PI).abs() < 1e-12, "{r}");
        assert_eq!(h, 1.0);
        assert_eq!(trace_at(&tr, 1.0).unwrap()[2], 2.0);
        assert!(trace_at(&tr, 1.01).is_none());
        assert!(trace_at(&tr, -0.01).is_none());
        assert!(trace_at(&Trace::default(), 0.0).is_none());
    }

    fn row(t_s: f64, roll_deg: f64, height_m: f64) -> TruthRow {
        TruthRow {
            t_s,
            distance_m: 0.0,
            speed_mps: 0.0,
            heading_rad: 0.0,
            pitch_rad: 0.0,
            roll_rad: roll_deg.to_radians(),
            height_m,
            north_m: 0.0,
            east_m: 0.0,
            down_m: 0.0,
        }
    }

    #[test]
    fn scores_of_a_hand_example() {
        // Navigator: roll 0 throughout, height rising 1 m/s. Truth rows at 0 (the start, not
        // scored), 1, 2 s: roll 3° and −4°, height 0. Pitch errors are zero, so the pooled RMSE
        // is sqrt((9 + 16 + 0 + 0) / 4) = 2.5°.
        let tr = trace(&[0.0, 1.0, 2.0], &[0.0; 3], &[0.0, 1.0, 2.0]);
        let truth = [row(0.0, 0.0, 0.0), row(1.0, 3.0, 0.0), row(2.0, -4.0, 0.0)];
        let s = score(Some(2), &tr, &truth, 0);
        assert_eq!(s.rows, 2);
        assert!((s.roll_rmse_deg - 12.5_f64.sqrt()).abs() < 1e-12);
        assert_eq!(s.pitch_rmse_deg, 0.0);
        assert!((s.roll_pitch_rmse_deg - 2.5).abs() < 1e-12);
        assert_eq!(s.height_error_m, 2.0);
        assert_eq!(s.height_error_max_m, 2.0);
        // Truth beyond the trace is not scored.
        let s = score(None, &tr, &[row(0.0, 0.0, 0.0), row(5.0, 1.0, 0.0)], 0);
        assert_eq!(s.rows, 0);
        assert!(s.roll_pitch_rmse_deg.is_nan() && s.height_error_m.is_nan());
    }
}
