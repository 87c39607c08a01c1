//! A four-IMU quadrotor flight as one redundant block.
//!
//! Unit k's gyro and accelerometer triads are channels 3k..3k+3, each in the unit's own axes
//! (FRD, as the loader gives them: repaired, aligned on the reference unit's rows, residual lags
//! resampled away). Channel 3k+i senses along column i of `R_k = vehicle_from_reference ·
//! installation_k`, the unit's rotation into the vehicle frame that the evaluation uses; with
//! those axes and equal weights, fusion's least squares over the channels is the mean of the
//! units turned into the vehicle frame, which is what the evaluation's fused run navigates
//! ([`crate::quadrotor_nav::frames::fused`]).
//!
//! Row j is at `t0 + j/120 s` on the trial's time base, and its device time is
//! [`device_us`] of that, as the evaluation feeds its navigator.

use anyhow::{Result, anyhow};
use ipc_types::{Header, RawImu, Truth};
use nalgebra::{Rotation3, Vector3};
use rins_earth::LocalOrigin;
use rins_fusion::{Geometry, WlsSolver};
use rins_navigator::attitude::quaternion_from_euler;

use super::counts::{BlockQuantiser, Scales, largest_abs};
use super::fragment::{Axes, Fragment, NoiseDensity, StartTable, render};
use super::{ClockOffset, ImportedRun, Quantisation, RepairCount, central_difference, wxyz};
use crate::datasets::quadrotor::projection::{Installation, MAX_CHANNELS, estimate_installation};
use crate::datasets::quadrotor::{IMU_RATE_HZ, Repairs, Trial};
use crate::quadrotor_ahrs::run::device_us;
use crate::quadrotor_nav::frames::{self, Motion};
use crate::quadrotor_nav::run::start_from_truth;
use crate::quadrotor_nav::vehicle_from_reference;

/// Channel noise of the units: the Xsens DOT's datasheet class.
pub const NOISE: NoiseDensity = NoiseDensity {
    gyro_dps_rthz: 0.007,
    accel_ug_rthz: 120.0,
    source: "Xsens DOT datasheet (gyro 0.007 °/s/√Hz, accelerometer 120 µg/√Hz)",
};

/// Fault detection for four separate units on separate clocks on a flying airframe. Their
/// parity is not the datasheet noise of one converter: rotor vibration that differs from unit to
/// unit, scale-factor and installation errors in proportion to the motion, and sampling
/// instants up to a period apart. These are the settings `rins eval fdi` validated on these
/// recordings for the stacked rows (the operating point of its cross-validated ROC, the larger
/// motion-noise fraction, timing skew and noise-outlier ratio of its grid, the parity noise
/// learnt from the data over its learning and averaging lengths of 2 s and 10 s).
pub const SEPARATE_UNITS_FDI: &str = "[fusion.fdi]
# Four separate units on separate clocks (vibration, scale factor and installation errors,
# sampling instants): the settings `rins eval fdi` validated on these recordings.
false_alarm_probability = 1e-12
parity_noise = \"adaptive\"
learning_samples = 240        # 2 s at 120 Hz
adaptive_window = 1200        # 10 s at 120 Hz
motion_noise_fraction = 0.05
timing_skew_s = 0.01
noise_ratio = 60.0
";

/// The navigator profile the recording's configuration starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Profile<'a> {
    /// The profile's configuration text.
    pub text: &'a str,
    /// Its name, for a comment.
    pub name: &'a str,
    /// The navigator's initial latitude (rad), longitude (rad) and altitude (m) under that
    /// profile: the truth positions are placed about it.
    pub origin: [f64; 3],
}

/// The loader's repair counts, by kind, those that occurred.
pub fn repair_counts(r: &Repairs) -> Vec<RepairCount> {
    [
        ("counter_wraps", r.counter_wraps),
        ("repeated_timestamps", r.repeated_timestamps),
        ("missing_samples_filled", r.missing_samples_filled),
        ("non_finite_rows", r.non_finite_rows),
        ("rows_dropped", r.rows_dropped),
        ("imu_files_skipped", r.imu_files_skipped),
        ("trials_failed", r.trials_failed),
    ]
    .into_iter()
    .filter(|(_, n)| *n > 0)
    .map(|(kind, count)| RepairCount {
        kind: kind.to_string(),
        count,
    })
    .collect()
}

/// Each unit's rotation into the vehicle frame, in the installation's unit order.
pub fn unit_rotations(installation: &Installation) -> Vec<Rotation3<f64>> {
    let vehicle = vehicle_from_reference();
    installation
        .imus
        .iter()
        .map(|i| vehicle * i.rotation)
        .collect()
}

/// The sensing axes of the stacked channels: column i of unit k's rotation for channel 3k+i.
pub fn channel_axes(rotations: &[Rotation3<f64>]) -> Vec<[f64; 3]> {
    rotations
        .iter()
        .flat_map(|r| {
            (0..3).map(move |i| {
                let c = r.matrix().column(i);
                [c[0], c[1], c[2]]
            })
        })
        .collect()
}

/// The truth rows inside the IMU span as [`Truth`] samples about `origin`, and how many rows
/// fell outside.
fn truth_samples(trial: &Trial, motion: &Motion, origin: &LocalOrigin) -> (Vec<Truth>, usize) {
    let times: Vec<f64> = trial.truth.iter().map(|r| r.t_s).collect();
    let positions: Vec<[f64; 3]> = trial
        .truth
        .iter()
        .map(|r| [r.north_m, r.east_m, r.down_m])
        .collect();
    let velocity = central_difference(&times, &positions);
    let (first, last) = (motion.t0_s, motion.end_s());
    let last_row = motion.samples.len().saturating_sub(1);
    let mut out = Vec::with_capacity(trial.truth.len());
    for (row, v) in trial.truth.iter().zip(velocity) {
        if !(row.t_s >= first && row.t_s <= last) {
            continue;
        }
        let nearest = ((row.t_s - first) / motion.dt_s)
            .round()
            .clamp(0.0, last_row as f64);
        // Height above take-off, not the first row's down: the start's altitude is built the same.
        let [lat, lon, alt] = origin.geodetic([row.north_m, row.east_m, -row.height_m]);
        out.push(Truth {
            header: Header {
                origin_seq: nearest as u64,
                origin_device_time_us: device_us(row.t_s),
                ..Header::default()
            },
            quaternion: wxyz(&quaternion_from_euler(
                row.roll_rad,
                row.pitch_rad,
                row.heading_rad,
            )),
            velocity_ned_mps: v,
            latitude_rad: lat,
            longitude_rad: lon,
            altitude_m: alt,
            ..Truth::default()
        });
    }
    let outside = trial.truth.len() - out.len();
    (out, outside)
}

/// Quantises every unit's triads into frames of `3 · units` channels (channel 3k+i: axis i of
/// unit k).
fn frames_of(trial: &Trial, motion: &Motion, scales: &Scales) -> (Vec<RawImu>, Quantisation) {
    let n = (3 * trial.imus.len()).min(MAX_CHANNELS);
    let mut block = BlockQuantiser::new(scales);
    let mut frames = Vec::with_capacity(trial.len());
    let (mut gyro, mut accel) = ([0.0; MAX_CHANNELS], [0.0; MAX_CHANNELS]);
    for j in 0..trial.len() {
        for (k, series) in trial.imus.iter().enumerate().take(n / 3) {
            let s = &series.samples[j];
            gyro[3 * k..3 * k + 3].copy_from_slice(&s.gyro_rps);
            accel[3 * k..3 * k + 3].copy_from_slice(&s.accel_mps2);
        }
        let device = device_us(motion.time(j));
        frames.push(block.frame(j as u64, device, &gyro[..n], &accel[..n]));
    }
    (frames, block.quantisation())
}

/// Largest difference, over the frames whose channels are all valid, between the equal-weight
/// least squares of the frames' counts (converted with `scales`, along `axes`) and `motion`'s
/// samples: gyro rad/s, accelerometer m/s². What the import changes in what fusion computes.
pub fn fused_difference(
    frames: &[RawImu],
    axes: &[[f64; 3]],
    scales: &Scales,
    motion: &Motion,
) -> Result<[f64; 2]> {
    let geometry = Geometry::from_axes(axes).map_err(|e| anyhow!("channel axes: {e}"))?;
    let solver = WlsSolver::new(&geometry, geometry.full_mask(), &vec![1.0; geometry.n()])
        .map_err(|e| anyhow!("least squares over the channel axes: {e}"))?;
    let n = axes.len();
    let all = (0..n).fold(0u32, |m, ch| m | 1 << ch | 1 << (16 + ch));
    let mut largest = [0.0f64; 2];
    let (mut g, mut a) = ([0.0; MAX_CHANNELS], [0.0; MAX_CHANNELS]);
    for (frame, reference) in frames.iter().zip(&motion.samples) {
        if frame.valid_mask & all != all {
            continue;
        }
        for ch in 0..n {
            g[ch] = f64::from(frame.gyro_counts[ch]) * scales.gyro_lsb_rps;
            a[ch] = f64::from(frame.accel_counts[ch]) * scales.accel_lsb_mps2;
        }
        let (rate, _) = solver.solve(&g[..n]);
        let (force, _) = solver.solve(&a[..n]);
        let d = |x: [f64; 3], y: [f64; 3]| (Vector3::from(x) - Vector3::from(y)).amax();
        largest[0] = largest[0].max(d(rate, reference.gyro_rps));
        largest[1] = largest[1].max(d(force, reference.accel_mps2));
    }
    Ok(largest)
}

/// Imports one loaded flight under `profile` (the UAV profile: the evaluation's navigator
/// settings). Errors name the trial.
pub fn import_trial(trial: &Trial, profile: &Profile<'_>) -> Result<ImportedRun> {
    let name = &trial.name;
    let installation = estimate_installation(trial)?;
    let motion = frames::fused(trial, &installation, &vehicle_from_reference())?;
    let axes = channel_axes(&unit_rotations(&installation));
    let largest_rate = largest_abs(
        trial
            .imus
            .iter()
            .flat_map(|s| s.samples.iter().flat_map(|x| x.gyro_rps)),
    );
    let largest_force = largest_abs(
        trial
            .imus
            .iter()
            .flat_map(|s| s.samples.iter().flat_map(|x| x.accel_mps2)),
    );
    let scales = Scales::above(largest_rate, largest_force)
        .ok_or_else(|| anyhow!("{name}: no finite IMU value to scale the converter to"))?;
    let (imu, quantisation) = frames_of(trial, &motion, &scales);

    let start = start_from_truth(&trial.truth, motion.t0_s, motion.end_s()).ok_or_else(|| {
        anyhow!(
            "{name}: no ground-truth row inside the IMU recording ({:.2}..{:.2} s) to start from",
            motion.t0_s,
            motion.end_s()
        )
    })?;
    let [lat, lon, alt] = profile.origin;
    let start_table = StartTable {
        time_s: device_us(start.t_s) as f64 / 1e6,
        euler_deg: start.euler_rad.map(f64::to_degrees),
        velocity_ned_mps: start.velocity_ned,
        altitude_m: alt + start.height_m,
    };
    let (truth, outside) = truth_samples(trial, &motion, &LocalOrigin::new(lat, lon, alt));

    let config_fragment = render(&Fragment {
        title: format!(
            "Quadrotor flight {name} (Hurwitz & Klein, {} Xsens DOT units at {IMU_RATE_HZ} Hz), imported.",
            trial.imus.len()
        ),
        profile: profile.text,
        profile_name: profile.name,
        scales,
        rate_hz: IMU_RATE_HZ,
        axes: Axes::Listed(axes.clone()),
        axes_comment: "Channel 3k+i is axis i (x, y, z) of unit k in the unit's own axes. Its axis below is\n\
                       that unit axis in the vehicle frame: the unit's installation, estimated from the\n\
                       gyro data against the reference unit, turned by the reference's rotation into the\n\
                       vehicle frame. Equal weights: the least squares is the mean of the units.",
        noise: NOISE,
        fdi: Some(SEPARATE_UNITS_FDI),
        start: Some(start_table),
        origin_deg: [lat.to_degrees(), lon.to_degrees(), alt],
    });

    let fused = fused_difference(&imu, &axes, &scales, &motion)?;
    let mut notes = trial.notes.clone();
    if outside > 0 {
        notes.push(format!(
            "{outside} truth rows outside the IMU span ({:.3}..{:.3} s) left out",
            motion.t0_s,
            motion.end_s()
        ));
    }
    notes.push(format!(
        "fused from the counts vs the evaluation's fused solution: {:.3e} rad/s, {:.3e} m/s² at most",
        fused[0], fused[1]
    ));
    let mut clock_offsets = vec![ClockOffset {
        clock: "truth".into(),
        offset_s: trial.truth_offset_s,
        how: "GT.csv times against the reference unit: body rates from the truth's attitude \
              matched to the unit's gyro"
            .into(),
    }];
    for series in &trial.imus {
        clock_offsets.push(ClockOffset {
            clock: format!("IMU_{}", series.imu),
            offset_s: series.truth_offset_s - trial.truth_offset_s,
            how: format!(
                "{} whole rows against the reference's rate magnitude, then a residual of \
                 {:+.3}..{:+.3} rows resampled away",
                series.lag_rows, series.residual_lag_rows[0], series.residual_lag_rows[1]
            ),
        });
    }
    Ok(ImportedRun {
        name: name.clone(),
        imu,
        truth,
        config_fragment,
        scales,
        rate_hz: IMU_RATE_HZ,
        quantisation,
        clock_offsets,
        repairs: repair_counts(&trial.repairs),
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::datasets::quadrotor::{ImuSample, ImuSeries, TruthRow};

    /// Four units turned by `mounts` (ω_k = R_kᵀ ω_ref), 8 s at 120 Hz from t = −0.3 s, with
    /// gyro biases, and a truth at 10 Hz flying north-east and climbing.
    fn synthetic() -> Trial {
        let mounts = [
            Rotation3::identity(),
            Rotation3::from_euler_angles(0.02, -0.01, 0.3),
            Rotation3::from_euler_angles(-0.05, 0.04, -2.0),
            Rotation3::from_euler_angles(0.1, 0.0, 3.0),
        ];
        let n = 960;
        let t = |j: usize| -0.3 + j as f64 / IMU_RATE_HZ;
        let imus = mounts
            .iter()
            .enumerate()
            .map(|(k, r)| ImuSeries {
                imu: k + 1,
                lag_rows: k as i64,
                residual_lag_rows: [0.0; 2],
                repairs: Repairs::default(),
                truth_offset_s: 0.1 + k as f64 / IMU_RATE_HZ,
                samples: (0..n)
                    .map(|j| {
                        let s = t(j);
                        let g = Vector3::new(
                            (2.0 * s).sin(),
                            0.5 * (3.1 * s).cos(),
                            0.3 * (0.7 * s).sin(),
                        );
                        let a = Vector3::new(0.4 * (1.3 * s).cos(), 0.2 * s.sin(), -9.8);
                        let bias = Vector3::new(0.01 * k as f64, -0.02, 0.005);
                        ImuSample {
                            t_s: s,
                            gyro_rps: (r.inverse() * g + bias).into(),
                            accel_mps2: (r.inverse() * a).into(),
                            euler_rad: [0.0; 3],
                        }
                    })
                    .collect(),
            })
            .collect();
        let truth = (0..80)
            .map(|i| {
                let s = -0.5 + i as f64 * 0.1;
                TruthRow {
                    t_s: s,
                    distance_m: 0.0,
                    speed_mps: 0.0,
                    heading_rad: 0.8,
                    pitch_rad: -0.05,
                    roll_rad: 0.1,
                    height_m: 3.0 + 0.5 * s,
                    north_m: 2.0 * s,
                    east_m: 1.0 * s,
                    down_m: -0.5 * s,
                }
            })
            .collect();
        Trial {
            name: "Horizontal/path_9".into(),
            path: "Horizontal/path_9".into(),
            imus,
            truth,
            truth_offset_s: 0.1,
            repairs: Repairs {
                repeated_timestamps: 2,
                ..Repairs::default()
            },
            notes: vec!["IMU_2 lags IMU_1 by 1 rows".into()],
        }
    }

    fn profile() -> Profile<'static> {
        Profile {
            text: "[navigator]\nalign_s = 1.0\n",
            name: "test profile",
            origin: [0.5, 0.1, 100.0],
        }
    }

    /// The fragment's scales and gyro and accelerometer axes, read back as a reader of the file
    /// would.
    fn read_back(text: &str) -> (Scales, Vec<[f64; 3]>, Vec<[f64; 3]>, toml::Table) {
        let table: toml::Table = toml::from_str(text).unwrap();
        let device = table["device"].as_table().unwrap();
        let scales = Scales::new(
            device["gyro_full_scale_dps"].as_float().unwrap(),
            device["accel_full_scale_g"].as_float().unwrap(),
        );
        assert_eq!(device["converter_bits"].as_integer(), Some(16));
        let axes = |sensor: &str| -> Vec<[f64; 3]> {
            table["fusion"]["geometry"][sensor]["axes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|a| {
                    let a = a.as_array().unwrap();
                    std::array::from_fn(|i| a[i].as_float().unwrap())
                })
                .collect()
        };
        let (gyro, accel) = (axes("gyro"), axes("accel"));
        (scales, gyro, accel, table)
    }

    #[test]
    fn counts_are_each_units_own_values_within_one_lsb_at_the_evaluations_times() {
        let trial = synthetic();
        let run = import_trial(&trial, &profile()).unwrap();
        assert_eq!(run.imu.len(), trial.len());
        let half = |lsb: f64| 0.5 * lsb * (1.0 + 1e-9);
        // Error feedback: one value is off by up to one count, each channel's running sum by at
        // most half of one.
        let one = |lsb: f64| 2.0 * half(lsb);
        let mut sums = [[0.0f64; 2]; 12];
        for (j, frame) in run.imu.iter().enumerate() {
            assert_eq!((frame.n_gyro, frame.n_accel), (12, 12));
            assert_eq!(frame.valid_mask, 0x0fff_0fff);
            let t = trial.imus[0].samples[0].t_s + j as f64 / IMU_RATE_HZ;
            assert_eq!(frame.header.origin_device_time_us, device_us(t));
            assert_eq!(frame.header.origin_seq, j as u64);
            for (k, series) in trial.imus.iter().enumerate() {
                let s = &series.samples[j];
                for i in 0..3 {
                    let g = f64::from(frame.gyro_counts[3 * k + i]) * run.scales.gyro_lsb_rps;
                    let a = f64::from(frame.accel_counts[3 * k + i]) * run.scales.accel_lsb_mps2;
                    assert!((g - s.gyro_rps[i]).abs() <= one(run.scales.gyro_lsb_rps));
                    assert!((a - s.accel_mps2[i]).abs() <= one(run.scales.accel_lsb_mps2));
                    let sum = &mut sums[3 * k + i];
                    sum[0] += g - s.gyro_rps[i];
                    sum[1] += a - s.accel_mps2[i];
                    assert!(sum[0].abs() <= half(run.scales.gyro_lsb_rps) + 1e-12);
                    assert!(sum[1].abs() <= half(run.scales.accel_lsb_mps2) + 1e-12);
                }
            }
        }
        let rx: Vec<u64> = run.imu.iter().map(|f| f.header.origin_rx_ns).collect();
        assert!(rx.windows(2).all(|w| w[1] > w[0]));
        assert!(run.quantisation.gyro_max_error_rps <= one(run.scales.gyro_lsb_rps));
        assert_eq!(run.quantisation.clamped, 0);
        // The largest value is near, and below, the top of the range.
        let top = run
            .imu
            .iter()
            .flat_map(|f| f.gyro_counts[..12].iter().map(|c| c.unsigned_abs()))
            .max()
            .unwrap();
        assert!((32_700..32_767).contains(&top), "{top}");
        assert_eq!(run.repairs[0].kind, "repeated_timestamps");
        assert_eq!(run.clock_offsets.len(), 5);
        assert!((run.clock_offsets[2].offset_s - 1.0 / IMU_RATE_HZ).abs() < 1e-12);
    }

    #[test]
    fn fused_least_squares_of_the_imported_channels_is_the_evaluations_fused_solution() {
        let trial = synthetic();
        let run = import_trial(&trial, &profile()).unwrap();
        let (scales, gyro_axes, accel_axes, _) = read_back(&run.config_fragment);
        assert_eq!(scales, run.scales);
        assert_eq!(gyro_axes, accel_axes);
        let installation = estimate_installation(&trial).unwrap();
        let motion = frames::fused(&trial, &installation, &vehicle_from_reference()).unwrap();
        let [gyro, accel] = fused_difference(&run.imu, &gyro_axes, &scales, &motion).unwrap();
        // Each channel is off by at most one count (error feedback); the mean of four rotated
        // triads by at most that times √3 on any axis.
        let bound = |lsb: f64| lsb * 3f64.sqrt() + 1e-12;
        assert!(gyro <= bound(scales.gyro_lsb_rps), "{gyro}");
        assert!(accel <= bound(scales.accel_lsb_mps2), "{accel}");
        assert!(gyro > 0.0, "the counts do quantise");
    }

    #[test]
    fn start_and_truth_follow_the_reference_at_the_evaluations_start() {
        let trial = synthetic();
        let p = profile();
        let run = import_trial(&trial, &p).unwrap();
        let (_, _, _, table) = read_back(&run.config_fragment);
        let start = table["navigator"]["start"].as_table().unwrap();
        // The first truth row inside the IMU span with a row on either side: t = −0.3 s.
        let t0 = start_from_truth(&trial.truth, -0.3, 7.6).unwrap().t_s;
        assert_eq!(start["time_s"].as_float(), Some(device_us(t0) as f64 / 1e6));
        assert_eq!(start["roll_deg"].as_float(), Some(0.1f64.to_degrees()));
        assert_eq!(start["heading_deg"].as_float(), Some(0.8f64.to_degrees()));
        let v = start["velocity_ned_mps"].as_array().unwrap();
        assert!((v[0].as_float().unwrap() - 2.0).abs() < 1e-9);
        assert!((v[2].as_float().unwrap() + 0.5).abs() < 1e-9);
        let altitude = start["altitude_m"].as_float().unwrap();
        assert!((altitude - (100.0 + 3.0 + 0.5 * t0)).abs() < 1e-9);
        assert_eq!(table["fusion"]["rest_bias_s"].as_float(), Some(0.0));
        assert_eq!(table["navigator"]["align_s"].as_float(), Some(1.0));
        assert_eq!(
            table["navigator"]["initial_latitude_deg"].as_float(),
            Some(0.5f64.to_degrees())
        );

        // Truth rows inside −0.3..=7.675 s: t = −0.3 .. 7.4.
        assert_eq!(run.truth.len(), 78);
        let first = &run.truth[0];
        assert_eq!(first.header.origin_device_time_us, device_us(-0.3));
        assert_eq!(first.header.origin_seq, 0);
        let q = quaternion_from_euler(0.1, -0.05, 0.8);
        assert_eq!(first.quaternion, wxyz(&q));
        let origin = LocalOrigin::new(0.5, 0.1, 100.0);
        let ned = origin.ned(first.latitude_rad, first.longitude_rad, first.altitude_m);
        assert!(
            (ned[0] - -0.6).abs() < 1e-6 && (ned[1] - -0.3).abs() < 1e-6,
            "{ned:?}"
        );
        assert!((first.altitude_m - (100.0 + 3.0 - 0.15)).abs() < 1e-6);
        assert!((run.truth[5].velocity_ned_mps[1] - 1.0).abs() < 1e-9);
        assert!(run.notes.iter().any(|n| n.contains("2 truth rows outside")));
    }

    #[test]
    fn a_missing_reading_clears_its_valid_bit_only() {
        let mut trial = synthetic();
        // The loader removes rows with a non-finite value; a reading missing after it (the
        // installation is estimated on the gyros) is marked, not written.
        trial.imus[2].samples[10].accel_mps2[1] = f64::NAN;
        let run = import_trial(&trial, &profile()).unwrap();
        assert_eq!(run.imu[10].valid_mask, 0x0fff_0fff & !(1 << (16 + 7)));
        assert_eq!(run.imu[10].accel_counts[7], 0);
        assert_eq!(run.imu[11].valid_mask, 0x0fff_0fff);
        assert_eq!(run.quantisation.invalid_readings, 1);
    }

    #[test]
    fn a_trial_without_truth_inside_its_span_is_an_error_naming_it() {
        let mut trial = synthetic();
        trial.truth.iter_mut().for_each(|r| r.t_s += 100.0);
        let e = import_trial(&trial, &profile()).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("Horizontal/path_9: no ground-truth row"),
            "{e}"
        );
    }
}
