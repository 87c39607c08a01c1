//! Where a foot-mounted estimate loses distance, measured stride by stride against a reference
//! with a position per sample: the length of each stride (foot-down to foot-down, same sample
//! indices in both), and whether the stance detector fired while the reference foot was moving.

use serde::Serialize;

/// Reference foot speed above which the foot counts as moving, m/s. A foot flat on the floor
/// reads a few cm/s of Vicon marker jitter after the smoothing below.
pub const MOVING_SPEED_MPS: f64 = 0.1;
/// Samples either side averaged into the reference speed (Vicon positions are differentiated).
pub const SPEED_HALF_WINDOW: usize = 2;
/// Strides shorter than this (in the reference) are shuffles, not steps, and not counted, m.
pub const MIN_STRIDE_M: f64 = 0.2;

/// The stride-by-stride comparison of one trial.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StrideAnalysis {
    /// Strides counted (consecutive stance onsets at least [`MIN_STRIDE_M`] apart in the
    /// reference).
    pub strides: usize,
    /// Σ estimated stride length / Σ reference stride length (1 = no distance lost).
    pub length_ratio: f64,
    /// Fraction of the stance samples at which the reference foot moved faster than
    /// [`MOVING_SPEED_MPS`].
    pub stance_while_moving: f64,
    /// Mean reference foot speed over the stance samples, m/s.
    pub stance_mean_speed_mps: f64,
    /// Mean delay of the stance onset after the reference foot slowed below
    /// [`MOVING_SPEED_MPS`], s (negative: the detector fired before the foot stopped).
    pub onset_delay_s: f64,
    /// Mean delay of the stance end after the reference foot sped up past
    /// [`MOVING_SPEED_MPS`], s (positive: the detector held on while the foot was moving).
    pub end_delay_s: f64,
}

/// Reference speed per sample from positions at times `t_s`: central difference over
/// ±[`SPEED_HALF_WINDOW`] samples.
pub fn reference_speed(truth: &[[f64; 3]], t_s: &[f64]) -> Vec<f64> {
    let n = truth.len().min(t_s.len());
    (0..n)
        .map(|k| {
            let (a, b) = (
                k.saturating_sub(SPEED_HALF_WINDOW),
                (k + SPEED_HALF_WINDOW).min(n.saturating_sub(1)),
            );
            let dt = t_s[b] - t_s[a];
            if b <= a || dt <= 0.0 {
                return 0.0;
            }
            let d: f64 = (0..3).map(|i| (truth[b][i] - truth[a][i]).powi(2)).sum();
            d.sqrt() / dt
        })
        .collect()
}

fn horizontal(a: [f64; 3], b: [f64; 3]) -> f64 {
    (b[0] - a[0]).hypot(b[1] - a[1])
}

/// The nearest sample at or before `k` where `moving` changes to `to`, within `limit` samples.
fn last_change_before(moving: &[bool], k: usize, to: bool, limit: usize) -> Option<usize> {
    (k.saturating_sub(limit).max(1)..=k.min(moving.len().saturating_sub(1)))
        .rev()
        .find(|&i| moving[i] == to && moving[i - 1] != to)
}

/// Compares `estimate` (positions per sample, any horizontal frame: only lengths are used) and
/// the detector's `stance` flags with `truth` at times `t_s`.
pub fn analyse(
    estimate: &[[f64; 3]],
    stance: &[bool],
    truth: &[[f64; 3]],
    t_s: &[f64],
) -> StrideAnalysis {
    let n = estimate
        .len()
        .min(stance.len())
        .min(truth.len())
        .min(t_s.len());
    let speed = reference_speed(&truth[..n], &t_s[..n]);
    let moving: Vec<bool> = speed.iter().map(|&v| v > MOVING_SPEED_MPS).collect();
    let onsets: Vec<usize> = (1..n).filter(|&k| stance[k] && !stance[k - 1]).collect();
    let ends: Vec<usize> = (1..n).filter(|&k| !stance[k] && stance[k - 1]).collect();
    let (mut est, mut reference, mut strides) = (0.0, 0.0, 0);
    for w in onsets.windows(2) {
        let r = horizontal(truth[w[0]], truth[w[1]]);
        if r >= MIN_STRIDE_M {
            reference += r;
            est += horizontal(estimate[w[0]], estimate[w[1]]);
            strides += 1;
        }
    }
    let stance_idx: Vec<usize> = (0..n).filter(|&k| stance[k]).collect();
    let share = |f: &dyn Fn(usize) -> f64| {
        if stance_idx.is_empty() {
            f64::NAN
        } else {
            stance_idx.iter().map(|&k| f(k)).sum::<f64>() / stance_idx.len() as f64
        }
    };
    // Up to half a second back from each detector change to the reference's matching change.
    let limit = 100;
    let delays = |changes: &[usize], to_moving: bool| {
        let d: Vec<f64> = changes
            .iter()
            .filter_map(|&k| {
                // The reference change nearest the detector's, looking back and forward.
                let back = last_change_before(&moving, k, to_moving, limit);
                let fwd = (k..(k + limit).min(n))
                    .find(|&i| i > 0 && moving[i] == to_moving && moving[i - 1] != to_moving);
                let pick = match (back, fwd) {
                    (Some(b), Some(f)) => Some(if k - b <= f - k { b } else { f }),
                    (b, f) => b.or(f),
                }?;
                Some(t_s[k] - t_s[pick])
            })
            .collect();
        if d.is_empty() {
            f64::NAN
        } else {
            d.iter().sum::<f64>() / d.len() as f64
        }
    };
    StrideAnalysis {
        strides,
        length_ratio: if reference > 0.0 {
            est / reference
        } else {
            f64::NAN
        },
        stance_while_moving: share(&|k| f64::from(u8::from(moving[k]))),
        stance_mean_speed_mps: share(&|k| speed[k]),
        onset_delay_s: delays(&onsets, false),
        end_delay_s: delays(&ends, true),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Five 1 m strides along x at 200 Hz: 0.5 s of swing at 2 m/s, 0.5 s still.
    fn walk() -> (Vec<[f64; 3]>, Vec<f64>, Vec<bool>) {
        let (mut truth, mut t, mut still) = (Vec::new(), Vec::new(), Vec::new());
        let mut x = 0.0;
        for k in 0..(5 * 200 + 100) {
            let phase = k % 200;
            let moving = k < 5 * 200 && phase < 100;
            if moving {
                x += 2.0 / 200.0;
            }
            truth.push([x, 0.0, 0.0]);
            t.push(k as f64 / 200.0);
            still.push(!moving);
        }
        (truth, t, still)
    }

    #[test]
    fn a_shrunk_estimate_reads_as_short_strides_and_a_late_stance_as_stance_while_moving() {
        let (truth, t, still) = walk();
        let shrunk: Vec<[f64; 3]> = truth.iter().map(|p| [0.95 * p[0], 0.0, 0.0]).collect();
        // Stance exactly when the foot is still, from the first stride's landing on.
        let stance: Vec<bool> = still
            .iter()
            .enumerate()
            .map(|(k, &s)| s && k >= 100)
            .collect();
        let a = analyse(&shrunk, &stance, &truth, &t);
        assert_eq!(a.strides, 4);
        assert!((a.length_ratio - 0.95).abs() < 1e-9, "{a:?}");
        // Only the samples where the smoothed speed straddles the change read as moving.
        assert!(a.stance_while_moving < 0.05, "{a:?}");
        // Stance held 20 samples (0.1 s) into every swing: those samples moved at 2 m/s.
        let late: Vec<bool> = (0..stance.len())
            .map(|k| stance[k] || (k >= 100 && k % 200 < 20 && k < 1000))
            .collect();
        let b = analyse(&truth, &late, &truth, &t);
        assert!((b.length_ratio - 1.0).abs() < 1e-9, "{b:?}");
        assert!(b.stance_while_moving > 0.1, "{b:?}");
        assert!((b.end_delay_s - 0.1).abs() < 0.02, "{b:?}");
    }
}
