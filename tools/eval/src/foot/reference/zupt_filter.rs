//! The 9-state error-state filter of the peer's method: position, velocity and attitude error in a
//! local level frame (x, y horizontal, z down; heading 0 at the start), strapdown propagation at a
//! fixed step `T`, and a zero-velocity pseudo-measurement `0 = v + n` whenever the detector says
//! stance.
//!
//! Propagation (sample `k`, body rate `ω_k`, specific force `f_k`, `C` body-to-level):
//! `q_k = q_{k−1} ⊗ exp(ω_k T / 2)`, `a = C_k f_k + [0, 0, g]`, `v_k = v_{k−1} + T a`,
//! `p_k = p_{k−1} + T v_k + T²/2 a`; covariance `P = F P Fᵀ + G Q Gᵀ` with
//! `F = [I T·I 0; 0 I −T[C_{k−1} f_k]×; 0 0 I]`, `G = [0 0; T C_{k−1} 0; 0 −T C_{k−1}]`,
//! `Q = diag(σ_acc² I, σ_gyro² I)`. Update: `K = P Hᵀ (H P Hᵀ + R)⁻¹`, `H = [0 I 0]`,
//! `δx = K (0 − v)`, position and velocity corrected additively, attitude by `exp(δε) ⊗ q`,
//! `P = (I − K H) P`.

use nalgebra::{Matrix3, SMatrix, UnitQuaternion, Vector3};

use super::shoe::{shoe_statistic, stance_below};

type Matrix9 = SMatrix<f64, 9, 9>;
type Matrix9x6 = SMatrix<f64, 9, 6>;

/// The method's parameters: the peer's values by default, only the threshold left to choose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReferenceConfig {
    /// Detector accelerometer noise σ_a, m/s².
    pub detector_sigma_a: f64,
    /// Detector gyro noise σ_ω, rad/s.
    pub detector_sigma_w: f64,
    /// Detector window W, samples.
    pub window: usize,
    /// Detector threshold γ.
    pub threshold: f64,
    /// Gravity, m/s².
    pub g: f64,
    /// Fixed integration step T, s.
    pub dt_s: f64,
    /// Process noise of the specific force, m/s² per sample.
    pub process_sigma_acc: f64,
    /// Process noise of the body rate, rad/s per sample.
    pub process_sigma_gyro: f64,
    /// Zero-velocity measurement σ, m/s.
    pub zupt_sigma_mps: f64,
    /// Samples averaged for the initial roll and pitch.
    pub level_samples: usize,
}

impl Default for ReferenceConfig {
    fn default() -> Self {
        Self {
            detector_sigma_a: 0.00098,
            detector_sigma_w: 8.7266463e-5,
            window: 5,
            // What `rins eval pyshoe` chooses for the method on all its trials (10^7.5); the
            // pyshoe evaluation itself scores each trial with the one chosen on the others.
            threshold: 10f64.powf(7.5),
            g: 9.8029,
            dt_s: 1.0 / 200.0,
            process_sigma_acc: 0.5,
            process_sigma_gyro: 0.5_f64.to_radians(),
            zupt_sigma_mps: 0.01,
            level_samples: 20,
        }
    }
}

/// The estimate over one recording.
#[derive(Debug, Clone, Default)]
pub struct ReferenceRun {
    /// Position per sample: x, y level, z down, m, from the start.
    pub position_m: Vec<[f64; 3]>,
    /// The detector's decision per sample.
    pub stance: Vec<bool>,
}

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Initial roll and pitch from the mean specific force of the first samples (z down at rest);
/// heading 0.
fn initial_attitude(accel: &[[f64; 3]], samples: usize) -> UnitQuaternion<f64> {
    let m = samples.clamp(1, accel.len().max(1));
    let mut mean = Vector3::zeros();
    for a in accel.iter().take(m) {
        mean += Vector3::from(*a) / m as f64;
    }
    let roll = (-mean.y).atan2(-mean.z);
    let pitch = mean.x.atan2(mean.y.hypot(mean.z));
    UnitQuaternion::from_euler_angles(roll, pitch, 0.0)
}

/// Runs the method over `accel`, `gyro` (body z down, SI) with the stance flags computed from
/// `statistic` (the SHOE statistic of the same samples) and `config.threshold`.
pub fn run_with_statistic(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    statistic: &[f64],
    config: &ReferenceConfig,
) -> ReferenceRun {
    let n = accel.len().min(gyro.len()).min(statistic.len());
    let stance = stance_below(&statistic[..n], config.threshold);
    let mut run = ReferenceRun {
        position_m: Vec::with_capacity(n),
        stance,
    };
    if n == 0 {
        return run;
    }
    let dt = config.dt_s;
    let mut q = initial_attitude(&accel[..n], config.level_samples);
    let (mut p, mut v) = (Vector3::zeros(), Vector3::<f64>::zeros());
    let mut cov = Matrix9::zeros();
    cov.fixed_view_mut::<3, 3>(0, 0)
        .copy_from(&(Matrix3::identity() * 1e-5f64.powi(2)));
    cov.fixed_view_mut::<3, 3>(3, 3)
        .copy_from(&(Matrix3::identity() * 1e-5f64.powi(2)));
    cov.fixed_view_mut::<3, 3>(6, 6)
        .copy_from(&(Matrix3::identity() * 0.1f64.to_radians().powi(2)));
    let mut q_noise = SMatrix::<f64, 6, 6>::zeros();
    for i in 0..3 {
        q_noise[(i, i)] = config.process_sigma_acc.powi(2);
        q_noise[(i + 3, i + 3)] = config.process_sigma_gyro.powi(2);
    }
    let r_noise = Matrix3::identity() * config.zupt_sigma_mps.powi(2);
    let gravity = Vector3::new(0.0, 0.0, config.g);
    run.position_m.push([0.0; 3]);
    for k in 1..n {
        let (f, w) = (Vector3::from(accel[k]), Vector3::from(gyro[k]));
        let c_prev = q.to_rotation_matrix().into_inner();
        q *= UnitQuaternion::from_scaled_axis(w * dt);
        let acc_n = q * f + gravity;
        v += acc_n * dt;
        p += v * dt + acc_n * (0.5 * dt * dt);

        let mut big_f = Matrix9::identity();
        big_f
            .fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(Matrix3::identity() * dt));
        big_f
            .fixed_view_mut::<3, 3>(3, 6)
            .copy_from(&(-skew(&(c_prev * f)) * dt));
        let mut big_g = Matrix9x6::zeros();
        big_g.fixed_view_mut::<3, 3>(3, 0).copy_from(&(c_prev * dt));
        big_g
            .fixed_view_mut::<3, 3>(6, 3)
            .copy_from(&(-c_prev * dt));
        cov = big_f * cov * big_f.transpose() + big_g * q_noise * big_g.transpose();
        cov = (cov + cov.transpose()) * 0.5;

        if run.stance[k] {
            let pht = cov.fixed_columns::<3>(3).into_owned();
            let s = cov.fixed_view::<3, 3>(3, 3) + r_noise;
            if let Some(s_inv) = s.try_inverse() {
                let gain = pht * s_inv;
                let dx = gain * (-v);
                p += dx.fixed_rows::<3>(0);
                v += dx.fixed_rows::<3>(3);
                let eps = Vector3::from(dx.fixed_rows::<3>(6));
                q = UnitQuaternion::from_scaled_axis(eps) * q;
                let mut kh = Matrix9::zeros();
                kh.fixed_columns_mut::<3>(3).copy_from(&gain);
                cov = (Matrix9::identity() - kh) * cov;
                cov = (cov + cov.transpose()) * 0.5;
            }
        }
        run.position_m.push([p.x, p.y, p.z]);
    }
    run
}

/// [`run_with_statistic`] with the SHOE statistic computed here.
pub fn run_reference(
    accel: &[[f64; 3]],
    gyro: &[[f64; 3]],
    config: &ReferenceConfig,
) -> ReferenceRun {
    let statistic = shoe_statistic(
        accel,
        gyro,
        config.window,
        config.detector_sigma_a,
        config.detector_sigma_w,
        config.g,
    );
    run_with_statistic(accel, gyro, &statistic, config)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level foot at 200 Hz: 1 s still, then `strides` strides of `length` m along x, each a
    /// 0.5 s swing with speed `L/T (1 − cos 2πt/T)` along x and a lift `z = −h/2 (1 − cos 2πt/T)`
    /// (so the specific force never reads still mid-swing), and a 0.5 s stance. Returns accel,
    /// gyro and the true x per sample.
    fn walk(strides: usize, length: f64, g: f64) -> (Vec<[f64; 3]>, Vec<[f64; 3]>, Vec<f64>) {
        let dt = 1.0 / 200.0;
        let swing = 100;
        let (mut acc, mut x) = (Vec::new(), Vec::new());
        let mut pos = 0.0;
        let still = |acc: &mut Vec<[f64; 3]>, x: &mut Vec<f64>, pos: f64, n: usize| {
            for _ in 0..n {
                acc.push([0.0, 0.0, -g]);
                x.push(pos);
            }
        };
        still(&mut acc, &mut x, pos, 200);
        let period = swing as f64 * dt;
        for _ in 0..strides {
            for k in 1..=swing {
                let t = k as f64 * dt;
                let w = 2.0 * std::f64::consts::PI / period;
                let lift = 0.1;
                acc.push([
                    length / period * w * (w * t).sin(),
                    0.0,
                    -lift / 2.0 * w * w * (w * t).cos() - g,
                ]);
                pos = x.last().copied().unwrap_or(0.0);
                let t0 = t - dt;
                // Exact displacement over the step: ∫ L/T (1 − cos ωt) dt.
                let integral = |t: f64| length / period * (t - (w * t).sin() / w);
                x.push(pos + integral(t) - integral(t0));
            }
            pos = x.last().copied().unwrap_or(0.0);
            still(&mut acc, &mut x, pos, 100);
        }
        let gyro = vec![[0.0; 3]; acc.len()];
        (acc, gyro, x)
    }

    #[test]
    fn a_synthetic_walk_is_followed_to_the_millimetre_and_every_stance_is_found() {
        let config = ReferenceConfig {
            threshold: 1e7,
            ..ReferenceConfig::default()
        };
        let (acc, gyro, x) = walk(8, 1.2, config.g);
        let run = run_reference(&acc, &gyro, &config);
        let end = run.position_m.last().copied().unwrap_or_default();
        let truth_end = x.last().copied().unwrap_or_default();
        assert!((truth_end - 9.6).abs() < 1e-9, "{truth_end}");
        // The rectangle rule against the exact integral leaves O(T²) per stride.
        assert!((end[0] - truth_end).abs() < 0.005, "{end:?}");
        // Vertically, the right-endpoint sum of the lift's acceleration `A cos ωt` (A = h ω²/2)
        // runs `A T/2 (1 − cos ωt)` fast, which integrates to `A T_swing T/2` per stride.
        let omega = 2.0 * std::f64::consts::PI / 0.5;
        let per_stride = 0.1 / 2.0 * omega * omega * 0.5 * config.dt_s / 2.0;
        assert!(end[1].abs() < 1e-9, "{end:?}");
        assert!(
            (end[2] - 8.0 * per_stride).abs() < 0.2 * 8.0 * per_stride,
            "{end:?}"
        );
        // Stance: the still second, and each stride's still half-second (blocks of 5 that
        // hold no swing sample).
        let stance = run.stance.iter().filter(|&&s| s).count();
        assert!((200 + 8 * 95..=200 + 8 * 100).contains(&stance), "{stance}");
        // Along the way, every still sample is where the truth is, to the millimetre.
        for (k, (p, t)) in run.position_m.iter().zip(&x).enumerate() {
            if !run.stance[k] {
                continue;
            }
            assert!((p[0] - t).abs() < 0.005, "sample {k}: {} against {t}", p[0]);
        }
    }

    #[test]
    fn a_tilted_still_unit_levels_and_stays_put() {
        let config = ReferenceConfig::default();
        // Pitched 10° nose up: f = (g sin θ, 0, −g cos θ).
        let th = 10f64.to_radians();
        let acc = vec![[config.g * th.sin(), 0.0, -config.g * th.cos()]; 400];
        let run = run_reference(&acc, &vec![[0.0; 3]; 400], &config);
        let end = run.position_m.last().copied().unwrap_or_default();
        assert!(end.iter().all(|v| v.abs() < 1e-9), "{end:?}");
    }
}
