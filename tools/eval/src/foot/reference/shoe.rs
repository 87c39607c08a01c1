//! The SHOE statistic as the peer evaluates it: over consecutive, non-overlapping blocks of `W`
//! samples,
//! `T = (1/W) Σ_block ( |a_k − g ā/|ā||² / σ_a² + |ω_k|² / σ_ω² )`, `ā` the block's mean
//! specific force, and every sample of the block gets its block's `T`. Stance is `T < γ`.

/// The statistic per sample. Samples after the last whole block keep 0, as in the peer's code
/// (so they read as stance).
pub fn shoe_statistic(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    window: usize,
    sigma_a: f64,
    sigma_w: f64,
    g: f64,
) -> Vec<f64> {
    let n = accel.len().min(gyro.len());
    let w = window.max(1);
    let (inv_a, inv_w) = (1.0 / (sigma_a * sigma_a), 1.0 / (sigma_w * sigma_w));
    let mut out = vec![0.0; n];
    let mut k = 0;
    while k + w <= n {
        let mut mean = [0.0; 3];
        for a in &accel[k..k + w] {
            for i in 0..3 {
                mean[i] += a[i] / w as f64;
            }
        }
        let norm = (mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]).sqrt();
        let up = if norm > 0.0 {
            mean.map(|m| g * m / norm)
        } else {
            [0.0; 3]
        };
        let mut t = 0.0;
        for s in k..k + w {
            let (a, r) = (accel[s], gyro[s]);
            t += inv_a * (0..3).map(|i| (a[i] - up[i]).powi(2)).sum::<f64>();
            t += inv_w * (0..3).map(|i| r[i] * r[i]).sum::<f64>();
        }
        out[k..k + w].fill(t / w as f64);
        k += w;
    }
    out
}

/// Stance flags: `statistic < threshold`.
pub fn stance_below(statistic: &[f64], threshold: f64) -> Vec<bool> {
    statistic.iter().map(|&t| t < threshold).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_still_unit_scores_its_noise_and_a_moving_one_scores_high() {
        let g = 9.8;
        let still_a = vec![[0.0, 0.0, -g]; 10];
        let still_w = vec![[0.0; 3]; 10];
        let t = shoe_statistic(&still_a, &still_w, 5, 0.01, 0.001, g);
        assert!(t.iter().all(|&v| v.abs() < 1e-9), "{t:?}");
        // One sample of the first block turning at 0.01 rad/s: (0.01/0.001)² / 5 = 20.
        let mut w = still_w.clone();
        w[2] = [0.01, 0.0, 0.0];
        let t = shoe_statistic(&still_a, &w, 5, 0.01, 0.001, g);
        assert!(t[..5].iter().all(|&v| (v - 20.0).abs() < 1e-9), "{t:?}");
        assert!(t[5..].iter().all(|&v| v.abs() < 1e-9), "{t:?}");
        assert_eq!(
            stance_below(&t, 10.0)[..6],
            [false, false, false, false, false, true]
        );
    }

    #[test]
    fn the_tail_after_the_last_whole_block_reads_as_stance() {
        let a = vec![[1.0, 0.0, -9.0]; 7];
        let w = vec![[1.0; 3]; 7];
        let t = shoe_statistic(&a, &w, 5, 0.01, 0.001, 9.8);
        assert!(t[..5].iter().all(|&v| v > 1e6));
        assert_eq!(t[5..], [0.0, 0.0]);
    }
}
