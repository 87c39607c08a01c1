//! Time alignment of the recordings.
//!
//! What the files show. The four IMU files of a trial share one time column: the same 1/120 s grid
//! from 0, with the same number of rows (a few rows of IMU_4 carry a timestamp one period late or
//! repeated, e.g. Horizontal/path_3 and path_4, while the data itself stays regular). The data are
//! nevertheless not simultaneous: matching the rate magnitudes |ω| (independent of how each unit
//! is mounted) finds constant offsets of 0–1 rows in the horizontal trials and 3–11 rows (up to
//! 92 ms) in the straight-line trials. The ground truth (10 Hz) also runs on its own clock: its
//! roll and pitch match the IMU's Euler angles best 0–0.7 s later.
//!
//! So: IMU series are aligned on the row index, each shifted by the constant lag that minimises
//! the mean squared difference of |ω| against the reference IMU; the truth time is shifted by the
//! offset that best matches its roll and pitch with the reference IMU's.

/// Most rows an IMU may be shifted against the reference (0.25 s at 120 Hz).
pub const MAX_LAG_ROWS: usize = 30;
/// Largest truth clock offset searched, s.
pub const MAX_TRUTH_OFFSET_S: f64 = 1.5;

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

/// Smallest variance of the IMU's roll plus pitch over the truth times for the offset to be
/// observable, rad² ((0.5°)²): a vehicle that does not tilt gives no timing information.
const MIN_ANGLE_VARIANCE: f64 = 7.6e-5;

/// Mean and variance accumulator for the difference of two angle series.
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

/// The offset δ (s, on a grid of `step_s`) such that truth at time t matches the IMU at t + δ:
/// minimises the summed variance of (truth − IMU) roll and pitch differences (a constant
/// difference is a mounting offset and is allowed). `imu_*` are uniform at `imu_t0`, `imu_dt`.
/// Offsets are tried from 0 outwards, so among equal fits the smallest wins. `None` when the
/// IMU hardly tilts or the series do not overlap.
pub(crate) fn estimate_truth_offset(
    truth: &[(f64, f64, f64)],
    imu_roll: &[f64],
    imu_pitch: &[f64],
    imu_t0: f64,
    imu_dt: f64,
    max_offset_s: f64,
    step_s: f64,
) -> Option<f64> {
    let steps = (max_offset_s / step_s).round() as i64;
    let mut best: Option<(f64, f64)> = None;
    // 0, 1, −1, 2, −2, …
    let offsets = (0..=2 * steps).map(|i| if i % 2 == 1 { (i + 1) / 2 } else { -(i / 2) });
    for k in offsets {
        let offset = k as f64 * step_s;
        let (mut roll, mut pitch) = (Spread::default(), Spread::default());
        let (mut imu_roll_spread, mut imu_pitch_spread) = (Spread::default(), Spread::default());
        for &(t, truth_roll, truth_pitch) in truth {
            let at = |s: &[f64]| interpolate_uniform(s, imu_t0, imu_dt, t + offset);
            let (Some(r), Some(p)) = (at(imu_roll), at(imu_pitch)) else {
                continue;
            };
            roll.push(truth_roll - r);
            pitch.push(truth_pitch - p);
            imu_roll_spread.push(r);
            imu_pitch_spread.push(p);
        }
        if roll.n < 0.5 * truth.len() as f64 || roll.n < 2.0 {
            continue;
        }
        if imu_roll_spread.variance() + imu_pitch_spread.variance() < MIN_ANGLE_VARIANCE {
            return None;
        }
        let cost = roll.variance() + pitch.variance();
        if best.is_none_or(|(c, _)| cost < c) {
            best = Some((cost, offset));
        }
    }
    best.map(|(_, offset)| offset)
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

    #[test]
    fn truth_offset_of_a_late_clock_with_a_mounting_offset() {
        let roll = signal(3000);
        let pitch: Vec<f64> = signal(3100)[100..].to_vec();
        // Truth at t equals the IMU at t + 0.4 s, plus a constant 0.02 rad pitch offset.
        let truth: Vec<(f64, f64, f64)> = (0..200)
            .map(|k| {
                let t = k as f64 * 0.1;
                let at = |s: &[f64]| interpolate_uniform(s, 0.0, 1.0 / 120.0, t + 0.4).unwrap();
                (t, at(&roll), at(&pitch) + 0.02)
            })
            .collect();
        let offset =
            estimate_truth_offset(&truth, &roll, &pitch, 0.0, 1.0 / 120.0, 1.0, 1.0 / 120.0)
                .unwrap();
        assert!((offset - 0.4).abs() < 1.0 / 120.0, "{offset}");
        let level = vec![0.0; 3000];
        let flat: Vec<(f64, f64, f64)> = (0..200).map(|k| (k as f64 * 0.1, 0.0, 0.0)).collect();
        let none = estimate_truth_offset(&flat, &level, &level, 0.0, 1.0 / 120.0, 1.0, 0.1);
        assert_eq!(none, None);
    }
}
