//! Sub-row, slowly varying lag between units that are not on one clock.
//!
//! After the whole-row alignment ([`super::align::estimate_lag`]) the units still disagree in
//! time by a fraction of a row that wanders during a flight (0.2–1.6 rows = 2–13 ms in
//! Horizontal/path_8). With the quadrotor's angular accelerations (tens of rad/s²) a 5 ms
//! skew alone makes the rate channels of two units disagree by several °/s, more than their
//! noise, so the parity test would see the clock, not the sensors. The residual lag is measured
//! over sliding windows of the rate magnitude |ω| (independent of the mounting) and each unit is
//! resampled onto the reference's instants by linear interpolation.

use super::ImuSample;

/// Length of one lag-measuring window, rows (4 s at 120 Hz).
pub const WINDOW_ROWS: usize = 480;
/// Spacing of the windows, rows (1 s).
pub const STEP_ROWS: usize = 120;
/// Largest residual lag searched, rows (the whole-row alignment leaves at most ±0.5 in theory;
/// drift adds to it).
pub const MAX_RESIDUAL_ROWS: f64 = 2.0;
/// Grid of the search, rows.
pub const GRID_ROWS: f64 = 0.05;

/// Linear interpolation of `s` at fractional row `x`, clamped to the ends.
pub fn at_row(s: &[f64], x: f64) -> f64 {
    if s.is_empty() {
        return f64::NAN;
    }
    let last = (s.len() - 1) as f64;
    let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, last) };
    let i = x.floor() as usize;
    if i + 1 >= s.len() {
        return s[s.len() - 1];
    }
    let f = x - i as f64;
    s[i] * (1.0 - f) + s[i + 1] * f
}

/// The residual lag of `b` against `a` (rows, positive: `b` is later) at every row: measured
/// per window by least squares on the grid, held constant before the first and after the last
/// window centre, linearly interpolated between them. Both series are already aligned on whole
/// rows and have the same length. Series shorter than one window get one estimate over all rows.
pub fn residual_lag(a: &[f64], b: &[f64]) -> Vec<f64> {
    let n = a.len().min(b.len());
    if n == 0 {
        return Vec::new();
    }
    let window = WINDOW_ROWS.min(n);
    let mut centres: Vec<(f64, f64)> = Vec::new();
    let mut start = 0;
    loop {
        let lag = best_lag(&a[..n], &b[..n], start, window);
        centres.push((start as f64 + window as f64 / 2.0, lag));
        if start + window + STEP_ROWS > n {
            break;
        }
        start += STEP_ROWS;
    }
    // A median of three against single windows whose minimum is ambiguous (vibration makes
    // the cost nearly flat within ±0.5 rows for a few windows).
    let smoothed: Vec<(f64, f64)> = (0..centres.len())
        .map(|k| {
            let lo = k.saturating_sub(1);
            let hi = (k + 1).min(centres.len() - 1);
            let mut v: Vec<f64> = centres[lo..=hi].iter().map(|c| c.1).collect();
            v.sort_by(f64::total_cmp);
            (centres[k].0, v[v.len() / 2])
        })
        .collect();
    (0..n)
        .map(|j| {
            let x = j as f64;
            match smoothed.iter().position(|c| c.0 >= x) {
                None => smoothed[smoothed.len() - 1].1,
                Some(0) => smoothed[0].1,
                Some(k) => {
                    let (x0, l0) = smoothed[k - 1];
                    let (x1, l1) = smoothed[k];
                    l0 + (l1 - l0) * (x - x0) / (x1 - x0)
                }
            }
        })
        .collect()
}

/// `samples` read at rows `j + lag[j]` (linear interpolation; angles along the short way
/// round), keeping the times of the grid.
pub fn resample(samples: &[ImuSample], lag: &[f64]) -> Vec<ImuSample> {
    let column = |f: &dyn Fn(&ImuSample) -> f64| samples.iter().map(f).collect::<Vec<f64>>();
    let gyro: [Vec<f64>; 3] = std::array::from_fn(|i| column(&|s| s.gyro_rps[i]));
    let accel: [Vec<f64>; 3] = std::array::from_fn(|i| column(&|s| s.accel_mps2[i]));
    samples
        .iter()
        .zip(lag)
        .enumerate()
        .map(|(j, (s, &l))| {
            let x = j as f64 + l;
            let k = (x.floor().max(0.0) as usize).min(samples.len() - 1);
            let k1 = (k + 1).min(samples.len() - 1);
            let f = (x - k as f64).clamp(0.0, 1.0);
            let euler = std::array::from_fn(|i| {
                let (e0, e1) = (samples[k].euler_rad[i], samples[k1].euler_rad[i]);
                let d = (e1 - e0 + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                    - std::f64::consts::PI;
                let e = e0 + f * d;
                (e + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
            });
            ImuSample {
                t_s: s.t_s,
                gyro_rps: std::array::from_fn(|i| at_row(&gyro[i], x)),
                accel_mps2: std::array::from_fn(|i| at_row(&accel[i], x)),
                euler_rad: euler,
            }
        })
        .collect()
}

/// The grid lag minimising Σ (a[j] − b(j + L))² over rows `start..start + window`.
fn best_lag(a: &[f64], b: &[f64], start: usize, window: usize) -> f64 {
    let steps = (MAX_RESIDUAL_ROWS / GRID_ROWS).round() as i64;
    let mut best = (f64::INFINITY, 0.0);
    // 0, +1, −1, +2, … so that among equal fits the smallest lag wins.
    for i in 0..=2 * steps {
        let k = if i % 2 == 1 { (i + 1) / 2 } else { -(i / 2) };
        let lag = k as f64 * GRID_ROWS;
        let cost: f64 = (start..start + window)
            .map(|j| (a[j] - at_row(b, j as f64 + lag)).powi(2))
            .sum();
        if cost < best.0 {
            best = (cost, lag);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;

    fn signal(t: f64) -> f64 {
        (3.0 * t).sin() + 0.5 * (7.3 * t).cos() + 0.2 * (19.0 * t).sin()
    }

    #[test]
    fn recovers_a_drifting_sub_row_lag() {
        let n = 4000;
        let dt = 1.0 / 120.0;
        // b records the motion lag(j) rows later: b[j] = a(t_j − lag·dt); lag drifts 0.3 → 1.1.
        let lag_true = |j: f64| 0.3 + 0.8 * j / n as f64;
        let a: Vec<f64> = (0..n).map(|j| signal(j as f64 * dt)).collect();
        let b: Vec<f64> = (0..n)
            .map(|j| signal((j as f64 - lag_true(j as f64)) * dt))
            .collect();
        let lag = residual_lag(&a, &b);
        assert_eq!(lag.len(), n);
        // Inside the span of window centres the error is the grid plus the linear drift within
        // a window (0.8 · 480 / 4000 / 2 ≈ 0.05 rows).
        for j in (WINDOW_ROWS / 2..n - WINDOW_ROWS / 2).step_by(97) {
            let e = lag[j] - lag_true(j as f64);
            assert!(
                e.abs() < 0.1,
                "row {j}: {} vs {}",
                lag[j],
                lag_true(j as f64)
            );
        }
    }

    #[test]
    fn resampling_shifts_values_and_wraps_angles() {
        let samples: Vec<ImuSample> = (0..4)
            .map(|j| ImuSample {
                t_s: j as f64,
                gyro_rps: [j as f64, 0.0, 0.0],
                accel_mps2: [0.0, 2.0 * j as f64, 0.0],
                euler_rad: [0.0, 0.0, if j < 2 { 3.1 } else { -3.1 }],
            })
            .collect();
        let out = resample(&samples, &[0.5; 4]);
        assert_eq!(out[0].t_s, 0.0);
        assert_eq!(out[0].gyro_rps[0], 0.5);
        assert_eq!(out[1].accel_mps2[1], 3.0);
        // Between 3.1 and −3.1 the short way is through ±π.
        assert!((out[1].euler_rad[2].abs() - std::f64::consts::PI).abs() < 1e-9);
        assert_eq!(out[3].gyro_rps[0], 3.0);
    }

    #[test]
    fn interpolation_clamps_at_the_ends() {
        let s = [0.0, 10.0, 20.0];
        assert_eq!(at_row(&s, 0.5), 5.0);
        assert_eq!(at_row(&s, -3.0), 0.0);
        assert_eq!(at_row(&s, 7.0), 20.0);
        assert!(at_row(&[], 1.0).is_nan());
        assert_eq!(residual_lag(&[], &[]), Vec::<f64>::new());
    }
}
