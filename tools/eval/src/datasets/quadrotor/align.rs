//! Time alignment of the recordings.
//!
//! What the files show. The four IMU files of a trial share one time column: the same 1/120 s grid
//! from 0, with the same number of rows (a few rows of IMU_4 carry a timestamp one period late or
//! repeated, e.g. Horizontal/path_3 and path_4, while the data itself stays regular). The data are
//! nevertheless not simultaneous: matching the rate magnitudes |ω| (independent of how each unit
//! is mounted) finds constant offsets of 0–1 rows in the horizontal trials and 3–11 rows (up to
//! 92 ms) in the straight-line trials. The ground truth (10 Hz) also runs on its own clock (see
//! [`super::clock`]).
//!
//! So: IMU series are aligned on the row index, each shifted by the constant lag that minimises
//! the mean squared difference of |ω| against the reference IMU.

/// Most rows an IMU may be shifted against the reference (0.25 s at 120 Hz).
pub const MAX_LAG_ROWS: usize = 30;

/// The lag L (rows) minimising the mean of `(a[j] − b[j + L])²` over the overlap, searched over
/// `−max_lag..=max_lag`; `None` when no lag leaves at least half of the shorter series overlapping.
/// A positive lag means `b` records the same motion L rows later than `a`.
pub fn estimate_lag(a: &[f64], b: &[f64], max_lag: usize) -> Option<i64> {
    let min_overlap = a.len().min(b.len()) / 2;
    let mut best: Option<(f64, i64)> = None;
    let max_lag = max_lag as i64;
    for lag in -max_lag..=max_lag {
        let start = 0.max(-lag) as usize;
        let end = (a.len() as i64).min(b.len() as i64 - lag).max(0) as usize;
        if end <= start || end - start < min_overlap.max(1) {
            continue;
        }
        let sum: f64 = (start..end)
            .map(|j| (a[j] - b[(j as i64 + lag) as usize]).powi(2))
            .sum();
        let cost = sum / (end - start) as f64;
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, lag));
        }
    }
    best.map(|(_, lag)| lag)
}

/// Linear interpolation of a uniformly sampled series (`t0`, period `dt`) at `t`; `None` outside.
pub(crate) fn interpolate_uniform(series: &[f64], t0: f64, dt: f64, t: f64) -> Option<f64> {
    let x = (t - t0) / dt;
    // NaN fails this test too.
    if x.is_nan() || x < 0.0 {
        return None;
    }
    let i = x.floor() as usize;
    if i + 1 >= series.len() {
        return (i + 1 == series.len() && x == i as f64).then(|| series[i]);
    }
    let f = x - i as f64;
    Some(series[i] * (1.0 - f) + series[i + 1] * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| {
                let t = k as f64 / 120.0;
                (3.0 * t).sin() + 0.5 * (7.3 * t).cos() + 0.2 * (19.0 * t).sin()
            })
            .collect()
    }

    #[test]
    fn finds_the_shift_of_a_delayed_copy() {
        let a = signal(2000);
        for lag in [-7i64, 0, 3, 11] {
            // b[j + lag] = a[j]
            let b: Vec<f64> = (0..2000i64)
                .map(|j| {
                    let src = (j - lag).clamp(0, 1999) as usize;
                    a[src]
                })
                .collect();
            assert_eq!(estimate_lag(&a, &b, 30), Some(lag));
        }
        assert_eq!(estimate_lag(&[1.0], &[], 3), None);
    }

    #[test]
    fn interpolation_inside_and_outside() {
        let s = [0.0, 10.0, 20.0];
        assert_eq!(interpolate_uniform(&s, 1.0, 0.5, 1.25), Some(5.0));
        assert_eq!(interpolate_uniform(&s, 1.0, 0.5, 2.0), Some(20.0));
        assert_eq!(interpolate_uniform(&s, 1.0, 0.5, 2.01), None);
        assert_eq!(interpolate_uniform(&s, 1.0, 0.5, 0.99), None);
    }
}
