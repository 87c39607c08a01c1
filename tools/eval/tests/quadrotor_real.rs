//! The quadrotor loader on the real recordings. The data are not in the repository: they
//! are read from `quadrotor-4imu` in the recordings directory (`$RINS_DATA_DIR`, else `<repo>/data`); every test here prints a note and returns when they are
//! absent ("..._when_present"). `-- --nocapture` shows the figures each test measures.

use std::path::PathBuf;

use nalgebra::Vector3;
use rins_eval::datasets::quadrotor::frame::body_rate_from_euler_rates;
use rins_eval::datasets::quadrotor::projection::{
    estimate_installation, project_to_pyramid, stack_triads,
};
use rins_eval::datasets::quadrotor::{IMU_RATE_HZ, Trial, list_trials, load_all};
use rins_eval::installation::{angle_between, estimate_relative_rotation, residual_rms};
use rins_fusion::{Geometry, GeometryConfig};

fn data_dir() -> Option<PathBuf> {
    rins_eval::datasets::recording_set("quadrotor-4imu")
}

fn trials() -> Option<Vec<Trial>> {
    let dir = data_dir()?;
    Some(load_all(&dir, |_, _| {}).unwrap())
}

fn rms(x: impl Iterator<Item = f64>) -> f64 {
    let (s, n) = x.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    (s / n.max(1) as f64).sqrt()
}

fn unwrap_angles(a: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(a.len());
    let mut offset = 0.0;
    for (k, &x) in a.iter().enumerate() {
        if k > 0 {
            let d = x - a[k - 1];
            if d > std::f64::consts::PI {
                offset -= std::f64::consts::TAU;
            } else if d < -std::f64::consts::PI {
                offset += std::f64::consts::TAU;
            }
        }
        out.push(x + offset);
    }
    out
}

#[test]
fn lists_and_loads_every_trial_when_present() {
    let Some(dir) = data_dir() else { return };
    let listed = list_trials(&dir).unwrap();
    let mut progress = Vec::new();
    let trials = load_all(&dir, |d, t| progress.push((d, t))).unwrap();
    assert_eq!(trials.len(), listed.len());
    assert_eq!(progress.last(), Some(&(listed.len(), listed.len())));
    assert!(!trials.is_empty());
    for (t, e) in trials.iter().zip(&listed) {
        println!(
            "{:22} IMUs {:?} rows {} ({:.1} s) truth {} rows, clock offset {:+.3} s; lags {:?}; notes {:?}",
            t.name,
            e.imus,
            t.len(),
            t.len() as f64 / IMU_RATE_HZ,
            t.truth.len(),
            t.truth_offset_s,
            t.imus.iter().map(|s| s.lag_rows).collect::<Vec<_>>(),
            t.notes
        );
        assert_eq!(t.name, e.name);
        assert_eq!(t.imus.len(), e.imus.len());
        assert!(t.len() > 1000, "{}: {} rows", t.name, t.len());
        // The common time base is the 120 Hz grid.
        let s = &t.imus[0].samples;
        let span = s[s.len() - 1].t_s - s[0].t_s;
        assert!(
            (span * IMU_RATE_HZ - (s.len() - 1) as f64).abs() < 2.5,
            "{}",
            t.name
        );
        assert!(t.truth_offset_s.abs() <= 1.5);
        // Every recording turns enough for the clock to be found from the gyro.
        assert!(
            !t.notes.iter().any(|n| n.contains("not estimable")),
            "{}: {:?}",
            t.name,
            t.notes
        );
        let offsets: Vec<String> = t
            .imus
            .iter()
            .map(|s| format!("IMU_{} {:+.4} s", s.imu, s.truth_offset_s))
            .collect();
        println!("{:22} truth → file offsets: {}", t.name, offsets.join(", "));
        for s in &t.imus {
            // A unit's own offset is the truth's plus its lag of at most MAX_LAG_ROWS + 2 rows.
            assert!((s.truth_offset_s - t.truth_offset_s).abs() <= 32.0 / IMU_RATE_HZ);
        }
        // The known defects of these files, repaired: IMU_4 of Horizontal/path_3 has one
        // repeated timestamp and one missing sample, of Horizontal/path_4 two repeated
        // timestamps; every other file is clean.
        let expected = |imu: usize| match (t.name.as_str(), imu) {
            ("Horizontal/path_3", 4) => (1, 1),
            ("Horizontal/path_4", 4) => (2, 0),
            _ => (0, 0),
        };
        for s in &t.imus {
            let r = s.repairs;
            assert_eq!(
                (r.repeated_timestamps, r.missing_samples_filled),
                expected(s.imu),
                "{} IMU_{}",
                t.name,
                s.imu
            );
            assert_eq!(
                (r.counter_wraps, r.rows_dropped, r.non_finite_rows),
                (0, 0, 0)
            );
        }
        assert_eq!(t.repairs.imu_files_skipped, 0);
    }
}

/// Moving average over `w` rows of each component.
fn smooth(v: &[Vector3<f64>], w: usize) -> Vec<Vector3<f64>> {
    v.windows(w)
        .map(|x| x.iter().sum::<Vector3<f64>>() / w as f64)
        .collect()
}

/// The FRD convention: the measured rates agree with the rates implied by the unit's own Euler
/// angles (central differences), and much worse with the sensor's z-up axes taken as FRD. Both
/// are averaged over 0.1 s, which removes the rotor vibration the gyros see and the Euler angles
/// (a filtered attitude) do not.
#[test]
fn gyro_agrees_with_euler_angle_rates_when_present() {
    let Some(trials) = trials() else { return };
    for trial in &trials {
        for series in &trial.imus {
            let s = &series.samples;
            let euler: Vec<[f64; 3]> = s.iter().map(|x| x.euler_rad).collect();
            let unwrapped: Vec<Vec<f64>> = (0..3)
                .map(|i| unwrap_angles(&euler.iter().map(|e| e[i]).collect::<Vec<_>>()))
                .collect();
            let dt = 1.0 / IMU_RATE_HZ;
            let (mut implied, mut measured, mut as_recorded) = (Vec::new(), Vec::new(), Vec::new());
            for j in 1..s.len() - 1 {
                let rates =
                    [0, 1, 2].map(|i| (unwrapped[i][j + 1] - unwrapped[i][j - 1]) / (2.0 * dt));
                implied.push(Vector3::from(body_rate_from_euler_rates(euler[j], rates)));
                let g = Vector3::from(s[j].gyro_rps);
                measured.push(g);
                as_recorded.push(Vector3::new(g.x, -g.y, -g.z));
            }
            let (implied, measured, as_recorded) = (
                smooth(&implied, 12),
                smooth(&measured, 12),
                smooth(&as_recorded, 12),
            );
            let residual = |m: &[Vector3<f64>]| {
                rms(m.iter().zip(&implied).map(|(a, b)| (a - b).norm())).to_degrees()
            };
            let (r, w) = (residual(&measured), residual(&as_recorded));
            let sig = rms(implied.iter().map(|v| v.norm())).to_degrees();
            println!(
                "{} IMU_{}: 0.1 s means, |ω − ω(Euler)| RMS {r:.2} °/s (z-up axes taken as FRD: {w:.2}); |ω(Euler)| RMS {sig:.2} °/s",
                trial.name, series.imu
            );
            // Strong rotation (the horizontal trials) leaves no doubt; the straight lines turn
            // little and their vibration residue weighs more.
            let limit = if sig > 20.0 { 0.1 } else { 0.5 };
            assert!(
                r < limit * w,
                "{} IMU_{}: {r} vs {w}",
                trial.name,
                series.imu
            );
        }
    }
}

/// The specific force levelled by the unit's own roll and pitch averages to about [0, 0, −g]
/// over a flight (the flights start and end slow, so the mean acceleration is small).
#[test]
fn levelled_specific_force_averages_to_minus_g_when_present() {
    let Some(trials) = trials() else { return };
    for trial in &trials {
        for series in &trial.imus {
            let mut sum = Vector3::zeros();
            for s in &series.samples {
                let [roll, pitch, _] = s.euler_rad;
                let level = nalgebra::Rotation3::from_euler_angles(roll, pitch, 0.0);
                sum += level * Vector3::from(s.accel_mps2);
            }
            let m = sum / series.samples.len() as f64;
            let duration = series.samples.len() as f64 / IMU_RATE_HZ;
            println!(
                "{} IMU_{}: mean levelled f = [{:.2}, {:.2}, {:.2}] m/s² over {duration:.1} s",
                trial.name, series.imu, m.x, m.y, m.z
            );
            assert!(
                m.x.abs() < 1.0 && m.y.abs() < 1.0,
                "{} IMU_{}: {m}",
                trial.name,
                series.imu
            );
            // The four units differ by up to ±0.5 m/s² on z (consistently in every trial).
            assert!(
                (m.z + 9.81).abs() < 0.7,
                "{} IMU_{}: {m}",
                trial.name,
                series.imu
            );
        }
    }
}

/// Wahba on the gyros. The figures are printed; the checks: every horizontal trial (strong
/// rotation) finds the same mounting of each unit within 1°, and a rotation fitted on the first
/// half of such a flight lowers the residual of the second half (physical, not an over-fit).
#[test]
fn relative_rotations_and_residuals_when_present() {
    let Some(trials) = trials() else { return };
    let mut horizontal: Vec<Vec<nalgebra::Rotation3<f64>>> = Vec::new();
    for trial in &trials {
        let inst = estimate_installation(trial).unwrap();
        for i in &inst.imus {
            println!(
                "{} IMU_{}: rotation {:.2}° (axis {:?}); residual |Δω| RMS °/s: unrotated {:.2}, rotated {:.2}, centred {:.2}, 0.1 s low-pass {:.2}; bias difference {:?} °/s",
                trial.name,
                i.imu,
                i.angle_deg,
                i.rotation
                    .axis()
                    .map(|a| [a.x, a.y, a.z].map(|c| (c * 100.0).round() / 100.0)),
                i.residual_unrotated_dps,
                i.residual_dps,
                i.residual_centred_dps,
                i.residual_low_pass_dps,
                i.bias_difference_dps.map(|b| (b * 100.0).round() / 100.0),
            );
            assert!(i.residual_centred_dps <= i.residual_dps + 1e-9);
        }
        if !trial.name.starts_with("Horizontal") || trial.imus.len() != 4 {
            continue;
        }
        horizontal.push(inst.imus.iter().map(|i| i.rotation).collect());
        let reference: Vec<[f64; 3]> = trial.imus[0].samples.iter().map(|s| s.gyro_rps).collect();
        let half = reference.len() / 2;
        for series in &trial.imus[1..] {
            let other: Vec<[f64; 3]> = series.samples.iter().map(|s| s.gyro_rps).collect();
            let r = estimate_relative_rotation(&reference[..half], &other[..half]).unwrap();
            let fitted = residual_rms(&reference[half..], &other[half..], &r).unwrap();
            let identity = residual_rms(
                &reference[half..],
                &other[half..],
                &nalgebra::Rotation3::identity(),
            )
            .unwrap();
            assert!(
                fitted < identity,
                "{} IMU_{}: held-out residual {fitted} ≥ unrotated {identity}",
                trial.name,
                series.imu
            );
        }
    }
    for k in 1..horizontal.first().map_or(0, Vec::len) {
        let spread: Vec<f64> = horizontal
            .iter()
            .map(|r| angle_between(&r[k], &horizontal[0][k]).to_degrees())
            .collect();
        println!(
            "IMU_{}: mounting in each horizontal trial vs the first, °: {spread:.2?}",
            k + 1
        );
        assert!(spread.iter().all(|&d| d < 1.0), "IMU_{}: {spread:?}", k + 1);
    }
}

/// Redundant channels from the real IMUs: channel i is IMU i's vector on h_i. If the four turned
/// vectors ω_i were equal, least squares over the channels would return exactly their mean ω̄;
/// in general `x̂ − ω̄ = Σ (HᵀH)⁻¹ h_i h_iᵀ (ω_i − ω̄)`, so `|x̂ − ω̄| ≤ λ_max((HᵀH)⁻¹)·2·√(Σ|ω_i − ω̄|²)`
/// at every sample (Cauchy–Schwarz over the four terms). A channel taken from the wrong IMU, axis
/// or frame breaks the bound.
#[test]
fn pyramid_and_stacked_channels_when_present() {
    let Some(trials) = trials() else { return };
    let geometry = GeometryConfig::seed_pyramid().build().unwrap();
    let h = nalgebra::Matrix4x3::from_fn(|r, c| geometry.axes()[r][c]);
    let normal_inverse = (h.transpose() * h).try_inverse().unwrap();
    let pseudo_inverse = normal_inverse * h.transpose();
    let lambda_max = normal_inverse.symmetric_eigenvalues().max();
    for trial in trials.iter().filter(|t| t.imus.len() == 4) {
        let inst = estimate_installation(trial).unwrap();
        let rows = project_to_pyramid(trial, &inst, &geometry).unwrap();
        let stacked = stack_triads(trial, &inst).unwrap();
        assert_eq!(rows.len(), trial.len());
        assert_eq!(stacked[0].n, 12);
        let (mut diff, mut spread) = (Vec::new(), Vec::new());
        for (j, row) in rows.iter().enumerate() {
            let z = nalgebra::Vector4::from_column_slice(&row.gyro_rps[..4]);
            let fused = pseudo_inverse * z;
            let triads: Vec<Vector3<f64>> = (0..4)
                .map(|k| Vector3::from_column_slice(&stacked[j].gyro_rps[3 * k..3 * k + 3]))
                .collect();
            let mean = triads.iter().sum::<Vector3<f64>>() / 4.0;
            let s = triads
                .iter()
                .map(|t| (t - mean).norm_squared())
                .sum::<f64>()
                .sqrt();
            let d = (fused - mean).norm();
            assert!(
                d <= lambda_max * 2.0 * s + 1e-12,
                "{} row {j}: {d} > bound",
                trial.name
            );
            diff.push(d);
            spread.push(s / 2.0);
            // Channel 0 comes from the reference IMU itself.
            let h0 = Vector3::from(geometry.axes()[0]);
            let g0 = Vector3::from(trial.imus[0].samples[j].gyro_rps);
            assert!((row.gyro_rps[0] - h0.dot(&g0)).abs() < 1e-12);
        }
        println!(
            "{}: |pyramid LS − mean of 4 triads| RMS {:.2} °/s; RMS spread of the triads about their mean {:.2} °/s",
            trial.name,
            rms(diff.into_iter()).to_degrees(),
            rms(spread.into_iter()).to_degrees()
        );
    }
    // The stacked layout is a valid geometry for the fuser.
    assert!(
        Geometry::from_axes(&rins_eval::datasets::quadrotor::projection::stacked_axes(4)).is_ok()
    );
}
