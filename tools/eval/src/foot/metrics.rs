//! Accuracy figures of a foot-mounted trajectory against its reference.

/// 2-D RMSE after moving the estimate's start onto the truth's start and turning it about the
/// vertical by the one angle that fits it best (least squares over the whole trial): the
/// initial heading, which a foot-mounted unit without a magnetometer cannot know. Both
/// trajectories are right-handed horizontal coordinates (east, north for the estimate).
/// Returns `(rmse_m, rotation_rad)`; NaN when there are no points.
pub fn aligned_rmse_2d(estimate: &[[f64; 2]], truth: &[[f64; 2]]) -> (f64, f64) {
    let n = estimate.len().min(truth.len());
    if n == 0 {
        return (f64::NAN, f64::NAN);
    }
    let (e0, t0) = (estimate[0], truth[0]);
    let rel = |p: [f64; 2], o: [f64; 2]| [p[0] - o[0], p[1] - o[1]];
    // Procrustes in 2-D, rotation only: θ = atan2(Σ e × t, Σ e · t).
    let (mut cross, mut dot) = (0.0, 0.0);
    for (e, t) in estimate.iter().zip(truth).take(n) {
        let (e, t) = (rel(*e, e0), rel(*t, t0));
        cross += e[0] * t[1] - e[1] * t[0];
        dot += e[0] * t[0] + e[1] * t[1];
    }
    let theta = cross.atan2(dot);
    let (s, c) = theta.sin_cos();
    let sum: f64 = estimate
        .iter()
        .zip(truth)
        .take(n)
        .map(|(e, t)| {
            let (e, t) = (rel(*e, e0), rel(*t, t0));
            let r = [c * e[0] - s * e[1], s * e[0] + c * e[1]];
            (r[0] - t[0]).powi(2) + (r[1] - t[1]).powi(2)
        })
        .sum();
    ((sum / n as f64).sqrt(), theta)
}

/// Displacement from the start at which the peer's evaluation fixes the heading, m.
pub const PEER_ALIGN_DISTANCE_M: f64 = 0.8;
/// The sample the peer's evaluation aligns on when the estimate never gets that far.
pub const PEER_FALLBACK_ALIGN_INDEX: usize = 300;

/// The peer's figure for one trial, and how it was aligned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeerArmse {
    /// Mean over the samples of `sqrt((dx² + dy²) / 2)`, m (unrounded).
    pub armse_m: f64,
    /// The sample both trajectories were aligned on.
    pub align_index: usize,
    /// Rotation applied to the estimate about the vertical, rad.
    pub rotation_rad: f64,
}

/// The pyshoe evaluation's "ARMSE" (Wagstaff, Peretroukhin and Kelly, "Robust data-driven
/// zero-velocity detection for foot-mounted inertial navigation", and the public code of that
/// paper), computed as that code computes it, so a figure beside it means the same thing:
/// 1. both trajectories are shifted to start at the origin;
/// 2. `d_i` is the estimate's horizontal displacement from its start at sample `i + 1`, and
///    `k` the first `i` with `d_i ≥ 0.8 m` ([`PEER_FALLBACK_ALIGN_INDEX`] if it never is);
///    the code then takes the estimate's position at sample `k` itself — one sample before the
///    one that reached 0.8 m — and the truth's at the same index;
/// 3. the estimate is turned about the vertical by the signed angle between those two
///    horizontal vectors (no least-squares fit);
/// 4. `e_t = sqrt(((x̂ − x)² + (ŷ − y)²) / 2)` per sample — the mean over the two axes inside
///    the root — and the figure is the mean of `e_t` over every sample.
///
/// The peer rounds the result to 1 mm; it is returned unrounded (see [`round_mm`]). NaN for
/// empty input; a zero-length alignment vector leaves the estimate unturned.
pub fn peer_armse_2d(estimate: &[[f64; 2]], truth: &[[f64; 2]]) -> PeerArmse {
    let n = estimate.len().min(truth.len());
    if n == 0 {
        return PeerArmse {
            armse_m: f64::NAN,
            align_index: 0,
            rotation_rad: 0.0,
        };
    }
    let (e0, t0) = (estimate[0], truth[0]);
    let rel = |p: [f64; 2], o: [f64; 2]| [p[0] - o[0], p[1] - o[1]];
    let align_index = (1..n)
        .find(|&i| {
            let d = rel(estimate[i], e0);
            d[0].hypot(d[1]) >= PEER_ALIGN_DISTANCE_M
        })
        .map_or(PEER_FALLBACK_ALIGN_INDEX, |i| i - 1)
        .min(n - 1);
    let v1 = rel(estimate[align_index], e0);
    let v2 = rel(truth[align_index], t0);
    let (n1, n2) = (v1[0].hypot(v1[1]), v2[0].hypot(v2[1]));
    let rotation_rad = if n1 > 0.0 && n2 > 0.0 {
        let cross = v1[0] * v2[1] - v1[1] * v2[0];
        let cos = ((v1[0] * v2[0] + v1[1] * v2[1]) / (n1 * n2)).min(1.0);
        // The code's sign(cross)·arccos: a zero cross product gives no turn even at 180°.
        cross.signum() * if cross == 0.0 { 0.0 } else { cos.acos() }
    } else {
        0.0
    };
    let (s, c) = rotation_rad.sin_cos();
    let sum: f64 = (0..n)
        .map(|i| {
            let (e, t) = (rel(estimate[i], e0), rel(truth[i], t0));
            let r = [c * e[0] - s * e[1], s * e[0] + c * e[1]];
            (((r[0] - t[0]).powi(2) + (r[1] - t[1]).powi(2)) / 2.0).sqrt()
        })
        .sum();
    PeerArmse {
        armse_m: sum / n as f64,
        align_index,
        rotation_rad,
    }
}

/// A figure in metres rounded to 1 mm, as the peer reports its ARMSE.
pub fn round_mm(m: f64) -> f64 {
    (m * 1000.0).round() / 1000.0
}

/// Horizontal distance walked: the path through the given foot-down positions (one per stance
/// phase), so the swing of the foot does not count.
pub fn path_length_2d(foot_down: &[[f64; 3]]) -> f64 {
    foot_down
        .windows(2)
        .map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1]))
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rotated_and_shifted_copy_has_zero_error_and_the_rotation_is_found() {
        let truth: Vec<[f64; 2]> = (0..50)
            .map(|k| {
                let t = k as f64 * 0.2;
                [t, (t * 0.7).sin()]
            })
            .collect();
        let angle: f64 = 0.6;
        let (s, c) = (-angle).sin_cos();
        let estimate: Vec<[f64; 2]> = truth
            .iter()
            .map(|p| [c * p[0] - s * p[1] + 5.0, s * p[0] + c * p[1] - 2.0])
            .collect();
        let (rmse, theta) = aligned_rmse_2d(&estimate, &truth);
        assert!(rmse < 1e-12, "{rmse}");
        assert!((theta - angle).abs() < 1e-12);
    }

    #[test]
    fn a_constant_offset_after_the_start_is_the_rmse() {
        let truth = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        let estimate = [[0.0, 0.0], [1.0, 0.3], [2.0, 0.0]];
        let (rmse, _) = aligned_rmse_2d(&estimate, &truth);
        // One point 0.3 m off (to first order; the fitted rotation takes a little of it).
        assert!(
            rmse > 0.15 && rmse < (0.09f64 / 3.0).sqrt() + 1e-12,
            "{rmse}"
        );
    }

    #[test]
    fn path_length_ignores_height() {
        let p = [[0.0, 0.0, 0.0], [3.0, 4.0, 1.0], [3.0, 4.0, 0.0]];
        assert_eq!(path_length_2d(&p), 5.0);
    }
    #[test]
    fn the_peer_metric_on_a_hand_computed_walk() {
        // Truth: straight along x, 0.5 m per sample, starting at (1, 1). The estimate starts at
        // (−2, 3), goes along y (its heading is 90° off) and overshoots the last step by 0.2 m.
        let truth = [[1.0, 1.0], [1.5, 1.0], [2.0, 1.0], [2.5, 1.0]];
        let estimate = [[-2.0, 3.0], [-2.0, 3.5], [-2.0, 4.0], [-2.0, 4.7]];
        // Displacements of samples 1, 2, 3: 0.5, 1.0, 1.7 → d_1 = 1.0 is the first ≥ 0.8, so the
        // code aligns on sample 1: estimate (0, 0.5), truth (0.5, 0). cross = 0·0 − 0.5·0.5 < 0,
        // cos = 0 → the estimate turns by −90°: (x, y) → (y, −x).
        let r = peer_armse_2d(&estimate, &truth);
        assert_eq!(r.align_index, 1);
        assert!(
            (r.rotation_rad + std::f64::consts::FRAC_PI_2).abs() < 1e-12,
            "{r:?}"
        );
        // Turned estimate: (0,0), (0.5,0), (1.0,0), (1.7,0) against (0,0), (0.5,0), (1,0), (1.5,0):
        // e = 0, 0, 0, sqrt(0.2² / 2) = 0.141421…; mean over 4 samples = 0.035355…
        let expected = (0.04_f64 / 2.0).sqrt() / 4.0;
        assert!((r.armse_m - expected).abs() < 1e-12, "{r:?}");
        assert_eq!(round_mm(r.armse_m), 0.035);
    }

    #[test]
    fn the_peer_metric_falls_back_to_its_fixed_sample_and_survives_a_still_estimate() {
        let truth: Vec<[f64; 2]> = (0..400).map(|k| [k as f64 * 1e-3, 0.0]).collect();
        let still = vec![[0.0, 0.0]; 400];
        let r = peer_armse_2d(&still, &truth);
        assert_eq!(
            (r.align_index, r.rotation_rad),
            (PEER_FALLBACK_ALIGN_INDEX, 0.0)
        );
        let mean_x: f64 = truth.iter().map(|p| p[0]).sum::<f64>() / 400.0;
        assert!((r.armse_m - mean_x / 2f64.sqrt()).abs() < 1e-12, "{r:?}");
        assert!(peer_armse_2d(&[], &[]).armse_m.is_nan());
        // Shorter than the fallback sample: the last sample is used.
        assert_eq!(peer_armse_2d(&still[..10], &truth[..10]).align_index, 9);
    }
}
