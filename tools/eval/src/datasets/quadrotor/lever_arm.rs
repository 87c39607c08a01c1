//! Lever arms between the units, estimated from the data and removed from the specific force.
//!
//! The four units sit at different places on the airframe, so on a rotating body their specific
//! forces differ by `K(t) (r_k − r̄)` with `K = [ω̇]× + [ω]×[ω]×` — metres times tens of rad/s²
//! in the quadrotor's manoeuvres, several m/s², far above the accelerometers' noise. A single
//! sensor block has no such term, so, as with the installation rotations, the arms are estimated
//! from each trial by the same fixed rule and their effect removed before any test:
//! least squares of `a_k − ā` (each unit against the mean of all, in the reference frame) on `K`,
//! with a constant (the relative bias) absorbed by centring, over the whole trial, on
//! [`SMOOTH_ROWS`]-row averages so vibration does not dominate `ω̇`.

use nalgebra::{Matrix3, Vector3};

use super::Trial;
use super::projection::Installation;

/// Moving average applied to ω and a before estimating the arms (33 ms at 120 Hz).
pub const SMOOTH_ROWS: usize = 4;

/// One unit's lever arm relative to the centroid of all units, reference frame, m.
pub type LeverArm = [f64; 3];

fn skew(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v[2], v[1], v[2], 0.0, -v[0], -v[1], v[0], 0.0)
}

/// Trailing moving average over `rows` (shorter at the start).
fn smooth(v: &[Vector3<f64>], rows: usize) -> Vec<Vector3<f64>> {
    (0..v.len())
        .map(|j| {
            let from = j.saturating_sub(rows.max(1) - 1);
            v[from..=j].iter().sum::<Vector3<f64>>() / (j - from + 1) as f64
        })
        .collect()
}

/// `K(t) = [ω̇]× + [ω]×[ω]×` per row from the mean rate of all units (reference frame), with ω̇
/// by central differences of the smoothed rate.
fn rotation_terms(trial: &Trial, installation: &Installation, rate_hz: f64) -> Vec<Matrix3<f64>> {
    let n = trial.len();
    let units = trial.imus.len().max(1) as f64;
    let omega: Vec<Vector3<f64>> = (0..n)
        .map(|j| {
            installation
                .imus
                .iter()
                .zip(&trial.imus)
                .map(|(inst, s)| inst.rotation * Vector3::from(s.samples[j].gyro_rps))
                .sum::<Vector3<f64>>()
                / units
        })
        .collect();
    let omega = smooth(&omega, SMOOTH_ROWS);
    (0..n)
        .map(|j| {
            let (a, b) = (j.saturating_sub(1), (j + 1).min(n - 1));
            let span = (b - a).max(1) as f64 / rate_hz;
            let omega_dot = (omega[b] - omega[a]) / span;
            let w = skew(&omega[j]);
            skew(&omega_dot) + w * w
        })
        .collect()
}

/// Every unit's arm relative to the centroid, reference frame, m; `None` for all when the motion
/// does not excite the arms (the normal matrix is singular).
pub fn estimate_lever_arms(
    trial: &Trial,
    installation: &Installation,
    rate_hz: f64,
) -> Vec<Option<LeverArm>> {
    let n = trial.len();
    if n < 3 || installation.imus.len() != trial.imus.len() {
        return vec![None; trial.imus.len()];
    }
    let k_rows = rotation_terms(trial, installation, rate_hz);
    let accel: Vec<Vec<Vector3<f64>>> = installation
        .imus
        .iter()
        .zip(&trial.imus)
        .map(|(inst, s)| {
            let a: Vec<Vector3<f64>> = s
                .samples
                .iter()
                .map(|x| inst.rotation * Vector3::from(x.accel_mps2))
                .collect();
            smooth(&a, SMOOTH_ROWS)
        })
        .collect();
    let units = accel.len() as f64;
    let mean_accel: Vec<Vector3<f64>> = (0..n)
        .map(|j| accel.iter().map(|a| a[j]).sum::<Vector3<f64>>() / units)
        .collect();
    let k_mean = k_rows.iter().sum::<Matrix3<f64>>() / n as f64;
    accel
        .iter()
        .map(|a| {
            let y: Vec<Vector3<f64>> = (0..n).map(|j| a[j] - mean_accel[j]).collect();
            let y_mean = y.iter().sum::<Vector3<f64>>() / n as f64;
            let mut normal = Matrix3::zeros();
            let mut rhs = Vector3::zeros();
            for (k, yj) in k_rows.iter().zip(&y) {
                let kc = k - k_mean;
                normal += kc.transpose() * kc;
                rhs += kc.transpose() * (yj - y_mean);
            }
            normal
                .try_inverse()
                .map(|inv| (inv * rhs).into())
                .filter(|d: &[f64; 3]| d.iter().all(|c| c.is_finite()))
        })
        .collect()
}

/// Removes each unit's lever-arm term `R_kᵀ K(t) d_k` from its specific force (own frame).
/// Units without an estimate are left as they are.
pub fn remove_lever_arms(
    trial: &mut Trial,
    installation: &Installation,
    arms: &[Option<LeverArm>],
    rate_hz: f64,
) {
    let k_rows = rotation_terms(trial, installation, rate_hz);
    for ((series, inst), arm) in trial.imus.iter_mut().zip(&installation.imus).zip(arms) {
        let Some(d) = arm else { continue };
        let d = Vector3::from(*d);
        for (s, k) in series.samples.iter_mut().zip(&k_rows) {
            let own = inst.rotation.inverse() * (k * d);
            for i in 0..3 {
                s.accel_mps2[i] -= own[i];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::datasets::quadrotor::{ImuSample, ImuSeries};
    use nalgebra::Rotation3;

    /// Rigid body turning about all axes; unit k at arm r_k sees f + K r_k.
    fn trial_with_arms(arms: &[[f64; 3]]) -> (Trial, Installation) {
        let rate = 120.0;
        let n = 2400;
        let omega = |t: f64| {
            Vector3::new(
                1.5 * (1.1 * t).sin(),
                1.2 * (0.7 * t).cos(),
                0.8 * (1.9 * t).sin(),
            )
        };
        let omega_dot = |t: f64| {
            Vector3::new(
                1.65 * (1.1 * t).cos(),
                -0.84 * (0.7 * t).sin(),
                1.52 * (1.9 * t).cos(),
            )
        };
        let imus = arms
            .iter()
            .enumerate()
            .map(|(k, r)| {
                ImuSeries::aligned(
                    k + 1,
                    (0..n)
                        .map(|j| {
                            let t = j as f64 / rate;
                            let w = omega(t);
                            let kk = skew(&omega_dot(t)) + skew(&w) * skew(&w);
                            let f = Vector3::new(0.3 * t.sin(), 0.0, -9.8) + kk * Vector3::from(*r);
                            ImuSample {
                                t_s: t,
                                gyro_rps: w.into(),
                                accel_mps2: f.into(),
                                euler_rad: [0.0; 3],
                            }
                        })
                        .collect(),
                )
            })
            .collect();
        let installation = Installation {
            reference_imu: 1,
            imus: (0..arms.len())
                .map(|k| {
                    crate::datasets::quadrotor::projection::ImuInstallation::fixture(
                        k + 1,
                        Rotation3::identity(),
                    )
                })
                .collect(),
        };
        (Trial::synthetic(imus), installation)
    }

    #[test]
    fn recovers_arms_relative_to_the_centroid_and_removes_them() {
        let arms = [
            [0.12, 0.10, 0.0],
            [-0.10, 0.11, 0.02],
            [-0.11, -0.12, 0.0],
            [0.09, -0.09, -0.02],
        ];
        let (mut trial, installation) = trial_with_arms(&arms);
        let centroid = [0, 1, 2].map(|i| arms.iter().map(|a| a[i]).sum::<f64>() / 4.0);
        let est = estimate_lever_arms(&trial, &installation, 120.0);
        for (e, a) in est.iter().zip(&arms) {
            let e = e.expect("excited");
            for i in 0..3 {
                // The smoothing and the finite-difference ω̇ bias the fit by a few mm at most.
                assert!((e[i] - (a[i] - centroid[i])).abs() < 5e-3, "{e:?} vs {a:?}");
            }
        }
        remove_lever_arms(&mut trial, &installation, &est, 120.0);
        // After removal the units agree to the residual of the fit.
        for j in (10..2390).step_by(37) {
            let a0 = Vector3::from(trial.imus[0].samples[j].accel_mps2);
            for s in &trial.imus[1..] {
                let d = (Vector3::from(s.samples[j].accel_mps2) - a0).norm();
                assert!(d < 0.05, "row {j}: {d}");
            }
        }
    }
}
