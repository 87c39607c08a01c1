//! Free-inertial navigation on the four-IMU quadrotor recordings (`rins eval quadrotor`), with
//! the navigator library in-process: how well each unit alone, and the four fused, keep roll,
//! pitch and height without any aiding.
//!
//! Per trial and per run (each unit alone, then the fused four):
//! 1. The unit's rate and specific force are turned into the vehicle frame ([`frames`]).
//! 2. The navigator's error-state filter starts from the truth at t0 — roll, pitch and heading,
//!    the velocity from the truth positions, the height — and is predicted on every sample
//!    after it, with the settings of the UAV profile ([`run`]).
//! 3. Its roll and pitch are compared with the truth's at every truth row after t0, and its
//!    height with the truth's height above take-off ([`metrics`]).
//!
//! One configuration for every trial: the profile, the installation rule and the start rule are
//! the same fixed rules everywhere; the truth is used at t0 only.

pub mod frames;
pub mod metrics;
pub mod report;
pub mod run;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, anyhow};
use nalgebra::Rotation3;
use rins_navigator::inertial_core::AidedConfig;
use serde::Serialize;

use crate::datasets::quadrotor::projection::estimate_installation;
use crate::datasets::quadrotor::{
    Repairs, SkippedTrial, Trial, list_trials, load_trial, nothing_evaluated,
};
use metrics::{Scores, max, mean, median, score};
use run::{navigate, start_from_truth};

/// The roll/pitch RMSE the fused solution should stay within, degrees.
pub const ROLL_PITCH_TARGET_DEG: f64 = 1.0;

/// Rotation from the reference unit's (IMU_1's) FRD frame into the vehicle's. The identity: the
/// reference unit's x axis is the airframe's nose (see [`crate::datasets::quadrotor::frame`]),
/// and its own roll and pitch (from the unit's onboard filter) follow the truth's within about
/// 1.3° on every recording, a difference that varies from trial to trial: no fixed tilt between
/// unit and airframe stands out of that filter's own error, and the data hold no other record
/// of how the unit sits.
pub fn vehicle_from_reference() -> Rotation3<f64> {
    Rotation3::identity()
}

/// One trial's figures.
#[derive(Debug, Clone, Serialize)]
pub struct TrialResult {
    /// `<group>/path_<N>`.
    pub name: String,
    /// From t0 to the last truth row scored, s.
    pub duration_s: f64,
    /// t0 on the trial's time base, s.
    pub start_s: f64,
    /// Each unit alone, in file order.
    pub single: Vec<Scores>,
    /// The units fused.
    pub fused: Scores,
    /// Median of the single units' roll/pitch RMSE, degrees.
    pub median_single_roll_pitch_rmse_deg: f64,
    /// The fused roll/pitch RMSE is below the median single unit's.
    pub fused_better_than_median_single: bool,
    /// Added to the truth file's times to put them on the reference unit's, s.
    pub truth_offset_s: f64,
    /// The same for each unit's own file (its lag included), in file order, s.
    pub unit_truth_offsets_s: Vec<f64>,
    /// What the loader repaired in the trial's files.
    pub repairs: Repairs,
}

/// The whole data set's figures.
#[derive(Debug, Clone, Serialize)]
pub struct QuadrotorReport {
    /// The data set directory evaluated.
    pub dir: PathBuf,
    /// Every trial's figures, in the order they were run.
    pub trials: Vec<TrialResult>,
    /// Mean over trials of the fused roll/pitch RMSE, degrees.
    pub roll_pitch_rmse_deg: f64,
    /// Mean over trials of the per-trial median single-unit roll/pitch RMSE, degrees.
    pub median_single_roll_pitch_rmse_deg: f64,
    /// The fused mean is below the median-single mean.
    pub fused_better_than_median_single: bool,
    /// Trials where the fused RMSE is below that trial's median single unit.
    pub trials_fused_better: usize,
    /// The roll/pitch RMSE the fused solution is held to, degrees ([`ROLL_PITCH_TARGET_DEG`]).
    pub roll_pitch_target_deg: f64,
    /// The fused mean roll/pitch RMSE is within [`ROLL_PITCH_TARGET_DEG`].
    pub roll_pitch_target_met: bool,
    /// Mean over trials of the fused |height error| at the end, m.
    pub fused_height_error_abs_mean_m: f64,
    /// Mean over trials of the per-trial median single-unit |height error| at the end, m.
    pub median_single_height_error_abs_mean_m: f64,
    /// Largest fused |height error| of any trial, m.
    pub fused_height_error_max_m: f64,
    /// Latitude of the profile's origin, which sets the gravity model, degrees.
    pub gravity_latitude_deg: f64,
    /// How gyro biases were handled.
    pub gyro_bias: &'static str,
    /// Trials listed but not evaluated, with the reason.
    pub skipped: Vec<SkippedTrial>,
    /// What the loader repaired over the evaluated trials; the skipped ones count as failed.
    pub repairs: Repairs,
}

/// What the report says about gyro biases.
pub const GYRO_BIAS_NOTE: &str = "not estimated: every recording starts in flight (no rest \
interval), and the truth is not used after t0";

/// The figures of one trial: each unit alone, then the fused units. `progress()` after each run.
pub fn evaluate_trial(
    trial: &Trial,
    config: &AidedConfig,
    progress: &mut dyn FnMut(),
) -> Result<TrialResult> {
    let installation = estimate_installation(trial)?;
    let fused = frames::fused(trial, &installation, &vehicle_from_reference())?;
    let start = start_from_truth(&trial.truth, fused.t0_s, fused.end_s()).ok_or_else(|| {
        anyhow!(
            "{}: no ground-truth row inside the IMU recording ({:.2}..{:.2} s) to start from",
            trial.name,
            fused.t0_s,
            fused.end_s()
        )
    })?;
    let mut single = Vec::with_capacity(trial.imus.len());
    for (index, series) in trial.imus.iter().enumerate() {
        let motion = frames::single(trial, &installation, &vehicle_from_reference(), index)?;
        let trace = navigate(&motion, &start, config);
        single.push(score(Some(series.imu), &trace, &trial.truth, start.row));
        progress();
    }
    let trace = navigate(&fused, &start, config);
    let fused = score(None, &trace, &trial.truth, start.row);
    progress();
    let end_s = trial
        .truth
        .iter()
        .skip(start.row)
        .map(|r| r.t_s)
        .rfind(|&t| trace.t_s.last().is_some_and(|&last| t <= last))
        .unwrap_or(start.t_s);
    let median_single = median(
        &single
            .iter()
            .map(|s| s.roll_pitch_rmse_deg)
            .collect::<Vec<_>>(),
    );
    Ok(TrialResult {
        name: trial.name.clone(),
        duration_s: end_s - start.t_s,
        start_s: start.t_s,
        fused_better_than_median_single: fused.roll_pitch_rmse_deg < median_single,
        median_single_roll_pitch_rmse_deg: median_single,
        single,
        fused,
        truth_offset_s: trial.truth_offset_s,
        unit_truth_offsets_s: trial.imus.iter().map(|s| s.truth_offset_s).collect(),
        repairs: trial.repairs,
    })
}

/// The data set directory must exist: the error names it.
pub fn require_data_dir(dir: &Path) -> Result<()> {
    if dir.is_dir() {
        Ok(())
    } else {
        Err(anyhow!(
            "eval quadrotor: data set directory {} does not exist or is not a directory; {}",
            dir.display(),
            crate::data::fetch_hint(dir)
        ))
    }
}

/// Every trial under `dir`; `progress(done, total)` after each navigator run.
pub fn evaluate(
    dir: &Path,
    config: &AidedConfig,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<QuadrotorReport> {
    require_data_dir(dir)?;
    let entries = list_trials(dir)
        .with_context(|| format!("eval quadrotor: cannot list trials in {}", dir.display()))?;
    if entries.is_empty() {
        return Err(anyhow!(
            "eval quadrotor: no trials (<group>/path_<N>/IMU_k.csv) in {}",
            dir.display()
        ));
    }
    let total: usize = entries.iter().map(|e| e.imus.len() + 1).sum();
    let mut done = 0;
    progress(done, total);
    let mut trials = Vec::with_capacity(entries.len());
    let mut skipped = Vec::new();
    for entry in &entries {
        // The runs of a trial that fails are still counted, so the bar ends at its total; the
        // trial is listed in the report with the reason.
        let before = done;
        let result = load_trial(&entry.path)
            .map_err(anyhow::Error::from)
            .and_then(|trial| {
                evaluate_trial(&trial, config, &mut || {
                    done += 1;
                    progress(done, total);
                })
            });
        done = before + entry.imus.len() + 1;
        progress(done, total);
        match result {
            Ok(result) => trials.push(result),
            Err(e) => skipped.push(SkippedTrial {
                trial: entry.name.clone(),
                reason: format!("{e:#}"),
            }),
        }
    }
    if trials.is_empty() {
        return Err(anyhow!("eval quadrotor: {}", nothing_evaluated(&skipped)));
    }
    Ok(summarise(dir, trials, skipped, config))
}

fn summarise(
    dir: &Path,
    trials: Vec<TrialResult>,
    skipped: Vec<SkippedTrial>,
    config: &AidedConfig,
) -> QuadrotorReport {
    let collect = |f: &dyn Fn(&TrialResult) -> f64| trials.iter().map(f).collect::<Vec<_>>();
    let fused = mean(&collect(&|t| t.fused.roll_pitch_rmse_deg));
    let median_single = mean(&collect(&|t| t.median_single_roll_pitch_rmse_deg));
    let median_single_height = mean(&collect(&|t| {
        median(
            &t.single
                .iter()
                .map(|s| s.height_error_m.abs())
                .collect::<Vec<_>>(),
        )
    }));
    QuadrotorReport {
        dir: dir.to_path_buf(),
        roll_pitch_rmse_deg: fused,
        median_single_roll_pitch_rmse_deg: median_single,
        fused_better_than_median_single: fused < median_single,
        trials_fused_better: trials
            .iter()
            .filter(|t| t.fused_better_than_median_single)
            .count(),
        roll_pitch_target_deg: ROLL_PITCH_TARGET_DEG,
        roll_pitch_target_met: fused <= ROLL_PITCH_TARGET_DEG,
        fused_height_error_abs_mean_m: mean(&collect(&|t| t.fused.height_error_m.abs())),
        median_single_height_error_abs_mean_m: median_single_height,
        fused_height_error_max_m: max(&collect(&|t| t.fused.height_error_max_m)),
        gravity_latitude_deg: config.origin[0].to_degrees(),
        gyro_bias: GYRO_BIAS_NOTE,
        repairs: trials.iter().fold(
            Repairs {
                trials_failed: skipped.len(),
                ..Repairs::default()
            },
            |total, t| total + t.repairs,
        ),
        trials,
        skipped,
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{Rotation3, Vector3};
    use rins_earth::normal_gravity;
    use rins_navigator::NavigatorConfig;
    use rins_navigator::mechanisation::quaternion_from_euler;

    use super::*;
    use crate::datasets::quadrotor::frame::body_rate_from_euler_rates;
    use crate::datasets::quadrotor::{IMU_RATE_HZ, ImuSample, ImuSeries, TruthRow};

    const SECONDS: f64 = 20.0;
    const HEIGHT_M: f64 = 10.0;

    /// Euler angles and their rates of a vehicle hovering in place while it rocks in roll and
    /// pitch (±17°, ±11°) and turns slowly: |ω|, |ω̇|, |ω̈| all stay below 0.4 (rad, s).
    fn euler(t: f64) -> ([f64; 3], [f64; 3]) {
        let (a, w1, b, w2, r) = (0.3, 1.1, 0.2, 0.7, 0.05);
        (
            [a * (w1 * t).sin(), b * (w2 * t).sin(), 1.0 + r * t],
            [a * w1 * (w1 * t).cos(), b * w2 * (w2 * t).cos(), r],
        )
    }

    /// Units mounted every which way: IMU k reads `R_kᵀ` of the vehicle's vectors.
    fn mounts() -> Vec<Rotation3<f64>> {
        vec![
            Rotation3::identity(),
            Rotation3::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
            Rotation3::from_euler_angles(std::f64::consts::PI, 0.1, -0.4),
            Rotation3::from_euler_angles(0.05, -0.03, 2.5),
        ]
    }

    /// A trial in which every unit senses the exact motion of [`euler`]: each sample is the
    /// rate and specific force at the middle of the interval it closes (the mean over the
    /// interval to second order), the truth is the exact attitude every 0.1 s at a constant
    /// height, and gravity is what the navigator computes at the profile's origin.
    fn synthetic(mounts: &[Rotation3<f64>], gyro_bias: &[[f64; 3]]) -> Trial {
        let cfg = config();
        let gravity = normal_gravity(cfg.origin[0], cfg.origin[2] + HEIGHT_M);
        let dt = 1.0 / IMU_RATE_HZ;
        let rows = (SECONDS * IMU_RATE_HZ) as usize + 1;
        let imus = mounts
            .iter()
            .zip(gyro_bias)
            .enumerate()
            .map(|(k, (mount, bias))| {
                ImuSeries::aligned(
                    k + 1,
                    (0..rows)
                        .map(|j| {
                            let t = j as f64 * dt;
                            let (e, rates) = euler(t - 0.5 * dt);
                            let omega = Vector3::from(body_rate_from_euler_rates(e, rates));
                            let c = quaternion_from_euler(e[0], e[1], e[2]);
                            let force = c.inverse() * Vector3::new(0.0, 0.0, -gravity);
                            let unit = mount.inverse();
                            ImuSample {
                                t_s: t,
                                gyro_rps: (unit * omega + Vector3::from(*bias)).into(),
                                accel_mps2: (unit * force).into(),
                                euler_rad: [0.0; 3],
                            }
                        })
                        .collect(),
                )
            })
            .collect();
        let truth = (0..=(SECONDS * 10.0) as usize)
            .map(|i| {
                let t_s = i as f64 * 0.1;
                let (e, _) = euler(t_s);
                TruthRow {
                    t_s,
                    distance_m: 0.0,
                    speed_mps: 0.0,
                    heading_rad: e[2].rem_euclid(std::f64::consts::TAU),
                    pitch_rad: e[1],
                    roll_rad: e[0],
                    height_m: HEIGHT_M,
                    north_m: 0.0,
                    east_m: 0.0,
                    down_m: 0.0,
                }
            })
            .collect();
        Trial {
            name: "synthetic/path_1".into(),
            path: "synthetic/path_1".into(),
            imus,
            truth,
            truth_offset_s: 0.0,
            repairs: Default::default(),
            notes: Vec::new(),
        }
    }

    fn config() -> AidedConfig {
        NavigatorConfig::default().aided_config()
    }

    /// With exact measurements the only errors are the installation estimate's (noise-free
    /// data: ~1e-12 rad) and the strapdown's truncation: a midpoint rate with the coning term
    /// leaves a third-order error per step of about (|ω̈| + |ω||ω̇|) Δt³ / 24 < 1.4e-8 rad, so
    /// at most 2400 · 1.4e-8 = 3.3e-5 rad (0.002°) after 20 s even if every step added up.
    /// That tilt leaks gravity into the vertical only at second order (g ε²/2 ≈ 5e-9 m/s²), so
    /// the height must hold to far better than a millimetre.
    #[test]
    fn exact_measurements_give_zero_error_for_every_unit_and_the_fused_units() {
        let trial = synthetic(&mounts(), &[[0.0; 3]; 4]);
        let mut runs = 0;
        let r = evaluate_trial(&trial, &config(), &mut || runs += 1).unwrap();
        assert_eq!(runs, 5);
        assert_eq!(r.single.len(), 4);
        // Truth rows 2..=200 are scored (row 1 is the start).
        assert!((r.duration_s - 19.9).abs() < 1e-9, "{}", r.duration_s);
        for s in r.single.iter().chain(std::iter::once(&r.fused)) {
            assert_eq!(s.rows, 199, "{s:?}");
            assert!(s.roll_pitch_rmse_deg < 0.002, "{s:?}");
            assert!(s.height_error_max_m < 1e-3, "{s:?}");
            assert_eq!(s.skipped_samples, 0);
        }
        assert_eq!(r.fused.imu, None);
        assert_eq!(r.single[2].imu, Some(3));
    }

    #[test]
    fn a_gyro_bias_is_not_removed_and_opposite_biases_cancel_in_the_fused_units() {
        // 0.5°/s on the vehicle's x axis for units 1 and 2, −0.5°/s for 3 and 4: each unit
        // drifts in roll, the fused rate does not.
        let b = 0.5_f64.to_radians();
        let m = mounts();
        let bias: Vec<[f64; 3]> = m
            .iter()
            .enumerate()
            .map(|(k, r)| {
                let sign = if k < 2 { 1.0 } else { -1.0 };
                (r.inverse() * Vector3::new(sign * b, 0.0, 0.0)).into()
            })
            .collect();
        let r = evaluate_trial(&synthetic(&m, &bias), &config(), &mut || ()).unwrap();
        for s in &r.single {
            // 0.5°/s over 20 s: roll error growing to ~10°, RMS a few degrees.
            assert!(s.roll_rmse_deg > 2.0, "{s:?}");
        }
        assert!(r.fused.roll_pitch_rmse_deg < 0.01, "{:?}", r.fused);
        assert!(r.fused_better_than_median_single);
    }

    #[test]
    fn no_truth_inside_the_recording_is_an_error_naming_the_trial() {
        let mut trial = synthetic(&mounts(), &[[0.0; 3]; 4]);
        trial.truth.iter_mut().for_each(|r| r.t_s += 100.0);
        let e = evaluate_trial(&trial, &config(), &mut || ()).unwrap_err();
        let msg = format!("{e:#}");
        assert!(
            msg.contains("synthetic/path_1") && msg.contains("no ground-truth row"),
            "{msg}"
        );
    }

    #[test]
    fn the_start_is_the_first_inner_truth_row_with_central_difference_velocity() {
        let mut truth = synthetic(&mounts()[..1], &[[0.0; 3]]).truth;
        for (i, r) in truth.iter_mut().enumerate() {
            r.north_m = 2.0 * r.t_s;
            r.east_m = -(i as f64 * 0.1).powi(2);
        }
        let s = run::start_from_truth(&truth, 0.25, 10.0).unwrap();
        assert_eq!(s.row, 3);
        assert!((s.velocity_ned[0] - 2.0).abs() < 1e-9);
        // d/dt of −t² at 0.3 s, exact for a parabola.
        assert!((s.velocity_ned[1] + 0.6).abs() < 1e-9);
        assert_eq!(s.height_m, HEIGHT_M);
        // Only the first and last rows inside the window: no neighbour on one side.
        assert!(run::start_from_truth(&truth[..2], 0.0, 10.0).is_none());
        assert!(run::start_from_truth(&truth, 50.0, 60.0).is_none());
    }

    #[test]
    fn fused_motion_is_the_mean_of_the_units_in_the_vehicle_frame() {
        let bias = [
            [0.01, 0.0, 0.0],
            [0.0, -0.02, 0.0],
            [0.0, 0.0, 0.03],
            [0.0; 3],
        ];
        let trial = synthetic(&mounts(), &bias);
        let inst = estimate_installation(&trial).unwrap();
        let v = vehicle_from_reference();
        let fused = frames::fused(&trial, &inst, &v).unwrap();
        let singles: Vec<frames::Motion> = (0..4)
            .map(|k| frames::single(&trial, &inst, &v, k).unwrap())
            .collect();
        assert!(frames::single(&trial, &inst, &v, 4).is_err());
        for j in [1, 500, 2400] {
            for axis in 0..3 {
                let mean_gyro = singles
                    .iter()
                    .map(|m| m.samples[j].gyro_rps[axis])
                    .sum::<f64>()
                    / 4.0;
                let mean_accel = singles
                    .iter()
                    .map(|m| m.samples[j].accel_mps2[axis])
                    .sum::<f64>()
                    / 4.0;
                assert!((fused.samples[j].gyro_rps[axis] - mean_gyro).abs() < 1e-12);
                assert!((fused.samples[j].accel_mps2[axis] - mean_accel).abs() < 1e-12);
            }
        }
        assert!((fused.time(12) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn missing_and_empty_directories_are_errors_naming_the_path() {
        let missing = Path::new("/nonexistent/quadrotor-data");
        let e = evaluate(missing, &config(), &mut |_, _| ()).unwrap_err();
        assert!(
            format!("{e:#}").contains("/nonexistent/quadrotor-data"),
            "{e:#}"
        );
        let empty =
            std::env::temp_dir().join(format!("rins-quadrotor-empty-{}", std::process::id()));
        std::fs::create_dir_all(&empty).unwrap();
        let e = evaluate(&empty, &config(), &mut |_, _| ()).unwrap_err();
        let msg = format!("{e:#}");
        std::fs::remove_dir_all(&empty).unwrap();
        assert!(
            msg.contains("no trials") && msg.contains(&*empty.to_string_lossy()),
            "{msg}"
        );
    }
}
