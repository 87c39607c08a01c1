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
}
