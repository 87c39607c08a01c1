//! The four IMUs in one frame, and redundant single-axis channels made from them.
//!
//! [`estimate_installation`] finds, for every IMU, the rotation into the reference IMU's frame
//! (Wahba on the paired gyro vectors; see [`crate::installation`]). The vectors are centred first:
//! a constant gyro bias of either unit then cancels exactly (`ω_ref − ω̄_ref = R (ω_k − ω̄_k)` holds
//! for constant biases), where left in it would pull the fit towards the bias difference.
//!
//! [`project_to_pyramid`] makes channel i from IMU i alone: its rate and specific force, turned into
//! the common frame, projected on the sensing axis h_i. Four single-axis channels with independent
//! errors, as on the product's sensor block. The lever arms between the units are ignored: the
//! rates are the same anywhere on a rigid body, the specific forces differ by ω×(ω×r) + ω̇×r.

use nalgebra::{Rotation3, Vector3};
use rins_fusion::Geometry;

use super::{ImuSample, Trial};
use crate::datasets::error::DatasetError;
use crate::installation::{estimate_relative_rotation, residual_rms, rotation_vector};

/// Most channels a row can carry (the IPC payloads' limit).
pub const MAX_CHANNELS: usize = ipc_types::MAX_CHANNELS;
/// Window of the moving average used to separate vibration from misalignment in the residual
/// (0.1 s at 120 Hz).
pub const LOW_PASS_ROWS: usize = 12;

/// How one IMU sits relative to the reference IMU, and how well their rates agree.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuInstallation {
    /// File number of the IMU.
    pub imu: usize,
    /// Rotation from this IMU's FRD frame into the reference IMU's.
    pub rotation: Rotation3<f64>,
    /// Angle of that rotation, degrees.
    pub angle_deg: f64,
    /// RMS of |ω_ref − ω_k| before rotating, °/s (biases included).
    pub residual_unrotated_dps: f64,
    /// RMS of |ω_ref − R ω_k| after rotating, °/s (biases included).
    pub residual_dps: f64,
    /// Same with each unit's mean rate removed (constant biases cancel), °/s.
    pub residual_centred_dps: f64,
    /// Centred residual after a 0.1 s moving average of both units: what is left once vibration
    /// is averaged out (misalignment, scale errors, bias drift), °/s.
    pub residual_low_pass_dps: f64,
    /// Mean rate difference `ω̄_ref − R ω̄_k`: the relative gyro bias, °/s.
    pub bias_difference_dps: [f64; 3],
}

impl ImuInstallation {
    /// A unit turned by `rotation` with no residuals: a test fixture.
    #[cfg(test)]
    pub(crate) fn fixture(imu: usize, rotation: Rotation3<f64>) -> Self {
        Self {
            imu,
            rotation,
            angle_deg: 0.0,
            residual_unrotated_dps: 0.0,
            residual_dps: 0.0,
            residual_centred_dps: 0.0,
            residual_low_pass_dps: 0.0,
            bias_difference_dps: [0.0; 3],
        }
    }
}

/// Every IMU of a trial against the reference (the first IMU, whose entry is the identity).
#[derive(Debug, Clone, PartialEq)]
pub struct Installation {
    /// File number of the reference IMU.
    pub reference_imu: usize,
    /// One entry per IMU of the trial, in the trial's order.
    pub imus: Vec<ImuInstallation>,
}

fn gyro_vectors(samples: &[ImuSample]) -> Vec<[f64; 3]> {
    samples.iter().map(|s| s.gyro_rps).collect()
}

fn mean(v: &[[f64; 3]]) -> [f64; 3] {
    let n = v.len().max(1) as f64;
    let s = v
        .iter()
        .fold([0.0; 3], |a, x| [a[0] + x[0], a[1] + x[1], a[2] + x[2]]);
    s.map(|c| c / n)
}

fn centred(v: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let m = mean(v);
    v.iter()
        .map(|x| [x[0] - m[0], x[1] - m[1], x[2] - m[2]])
        .collect()
}

fn moving_average(v: &[[f64; 3]], window: usize) -> Vec<[f64; 3]> {
    v.windows(window.max(1)).map(mean).collect()
}

/// Estimates every IMU's rotation into the reference IMU's frame from the trial's gyro data.
pub fn estimate_installation(trial: &Trial) -> Result<Installation, DatasetError> {
    let Some(reference) = trial.imus.first() else {
        return Err(DatasetError::Mismatch {
            trial: trial.name.clone(),
            reason: "no IMU".into(),
        });
    };
    let reference_raw = gyro_vectors(&reference.samples);
    let reference_centred = centred(&reference_raw);
    let reference_low = moving_average(&reference_centred, LOW_PASS_ROWS);
    let mut imus = Vec::with_capacity(trial.imus.len());
    for series in &trial.imus {
        let raw = gyro_vectors(&series.samples);
        let other_centred = centred(&raw);
        let rotation =
            estimate_relative_rotation(&reference_centred, &other_centred).map_err(|source| {
                DatasetError::Installation {
                    trial: trial.name.clone(),
                    imu: series.imu,
                    source,
                }
            })?;
        let dps = |x: Option<f64>| x.unwrap_or(f64::NAN).to_degrees();
        let low = moving_average(&other_centred, LOW_PASS_ROWS);
        let bias = Vector3::from(mean(&reference_raw)) - rotation * Vector3::from(mean(&raw));
        imus.push(ImuInstallation {
            imu: series.imu,
            rotation,
            angle_deg: rotation_vector(&rotation).norm().to_degrees(),
            residual_unrotated_dps: dps(residual_rms(&reference_raw, &raw, &Rotation3::identity())),
            residual_dps: dps(residual_rms(&reference_raw, &raw, &rotation)),
            residual_centred_dps: dps(residual_rms(&reference_centred, &other_centred, &rotation)),
            residual_low_pass_dps: dps(residual_rms(&reference_low, &low, &rotation)),
            bias_difference_dps: [bias.x, bias.y, bias.z].map(f64::to_degrees),
        });
    }
    Ok(Installation {
        reference_imu: reference.imu,
        imus,
    })
}

/// One time step of redundant channels.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChannelRow {
    /// Time on the trial's time base, s.
    pub t_s: f64,
    /// Channels in use (the rest of the arrays is zero).
    pub n: usize,
    /// Gyro channels, rad/s.
    pub gyro_rps: [f64; MAX_CHANNELS],
    /// Accelerometer channels, m/s².
    pub accel_mps2: [f64; MAX_CHANNELS],
}

impl ChannelRow {
    /// A row at `t_s` with `n` channels in use, every channel zero until filled.
    fn zeroed(t_s: f64, n: usize) -> Self {
        Self {
            t_s,
            n,
            gyro_rps: [0.0; MAX_CHANNELS],
            accel_mps2: [0.0; MAX_CHANNELS],
        }
    }
}

fn check_installation(trial: &Trial, installation: &Installation) -> Result<(), DatasetError> {
    let same = installation.imus.len() == trial.imus.len()
        && installation
            .imus
            .iter()
            .zip(&trial.imus)
            .all(|(a, b)| a.imu == b.imu);
    if same {
        Ok(())
    } else {
        Err(DatasetError::Mismatch {
            trial: trial.name.clone(),
            reason: "the installation was estimated for other IMUs".into(),
        })
    }
}

/// Channel i = IMU i's rate and specific force, turned into the reference frame, projected on
/// the geometry's axis h_i. Needs one axis per IMU.
pub fn project_to_pyramid(
    trial: &Trial,
    installation: &Installation,
    geometry: &Geometry,
) -> Result<Vec<ChannelRow>, DatasetError> {
    check_installation(trial, installation)?;
    let n = geometry.n();
    if n != trial.imus.len() {
        return Err(DatasetError::Mismatch {
            trial: trial.name.clone(),
            reason: format!(
                "the geometry has {n} axes but the trial {} IMUs: one channel per IMU",
                trial.imus.len()
            ),
        });
    }
    // Per channel, the row vector h_iᵀ R_i: projects IMU i's own vector straight onto h_i.
    let projectors: Vec<Vector3<f64>> = geometry
        .axes()
        .iter()
        .zip(&installation.imus)
        .map(|(h, inst)| inst.rotation.inverse() * Vector3::from(*h))
        .collect();
    Ok((0..trial.len())
        .map(|j| {
            let mut row = ChannelRow::zeroed(trial.imus[0].samples[j].t_s, n);
            for (i, (p, series)) in projectors.iter().zip(&trial.imus).enumerate() {
                let s = &series.samples[j];
                row.gyro_rps[i] = p.dot(&Vector3::from(s.gyro_rps));
                row.accel_mps2[i] = p.dot(&Vector3::from(s.accel_mps2));
            }
            row
        })
        .collect())
}

/// Every IMU's triad turned into the reference frame, IMU k on rows 3k..3k+3: 12 rows for four
/// IMUs, all along the reference axes (the geometry is `stacked_axes(trial.imus.len())`).
pub fn stack_triads(
    trial: &Trial,
    installation: &Installation,
) -> Result<Vec<ChannelRow>, DatasetError> {
    check_installation(trial, installation)?;
    let n = 3 * trial.imus.len();
    if n > MAX_CHANNELS {
        return Err(DatasetError::Mismatch {
            trial: trial.name.clone(),
            reason: format!("{n} rows exceed the {MAX_CHANNELS}-channel limit"),
        });
    }
    Ok((0..trial.len())
        .map(|j| {
            let mut row = ChannelRow::zeroed(trial.imus[0].samples[j].t_s, n);
            for (k, (inst, series)) in installation.imus.iter().zip(&trial.imus).enumerate() {
                let s = &series.samples[j];
                let g = inst.rotation * Vector3::from(s.gyro_rps);
                let a = inst.rotation * Vector3::from(s.accel_mps2);
                row.gyro_rps[3 * k..3 * k + 3].copy_from_slice(g.as_slice());
                row.accel_mps2[3 * k..3 * k + 3].copy_from_slice(a.as_slice());
            }
            row
        })
        .collect())
}

/// Axes of `count` triads along the reference axes (the geometry of [`stack_triads`]' rows).
pub fn stacked_axes(count: usize) -> Vec<[f64; 3]> {
    (0..count)
        .flat_map(|_| [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::ImuSeries;
    use super::*;

    /// A trial whose IMU k sees the reference's vectors through the rotation `mounts[k]`ᵀ, i.e.
    /// ω_k = R_kᵀ ω_ref, plus a constant gyro bias.
    fn synthetic(mounts: &[Rotation3<f64>]) -> Trial {
        let n = 600;
        let reference: Vec<([f64; 3], [f64; 3])> = (0..n)
            .map(|j| {
                let t = j as f64 / 120.0;
                (
                    [
                        (2.0 * t).sin(),
                        0.5 * (3.1 * t).cos(),
                        0.3 * (0.7 * t).sin(),
                    ],
                    [
                        0.4 * (1.3 * t).cos(),
                        0.2 * t.sin(),
                        -9.8 + 0.1 * (5.0 * t).sin(),
                    ],
                )
            })
            .collect();
        let imus = mounts
            .iter()
            .enumerate()
            .map(|(k, r)| {
                ImuSeries::aligned(
                    k + 1,
                    reference
                        .iter()
                        .enumerate()
                        .map(|(j, (g, a))| {
                            let bias = Vector3::new(0.01 * k as f64, -0.02, 0.005);
                            let gk = r.inverse() * Vector3::from(*g) + bias;
                            let ak = r.inverse() * Vector3::from(*a);
                            ImuSample {
                                t_s: j as f64 / 120.0,
                                gyro_rps: gk.into(),
                                accel_mps2: ak.into(),
                                euler_rad: [0.0; 3],
                            }
                        })
                        .collect(),
                )
            })
            .collect();
        Trial::synthetic(imus)
    }

    fn mounts() -> Vec<Rotation3<f64>> {
        vec![
            Rotation3::identity(),
            Rotation3::from_euler_angles(0.02, -0.01, 0.3),
            Rotation3::from_euler_angles(-0.05, 0.04, -2.0),
            Rotation3::from_euler_angles(0.1, 0.0, 3.0),
        ]
    }

    #[test]
    fn installation_recovers_the_mounts_despite_biases() {
        let m = mounts();
        let trial = synthetic(&m);
        let inst = estimate_installation(&trial).unwrap();
        for (i, r) in inst.imus.iter().zip(&m) {
            let error = crate::installation::angle_between(&i.rotation, r);
            assert!(error < 1e-9, "IMU {}: {error}", i.imu);
            assert!(i.residual_centred_dps < 1e-7, "{i:?}");
        }
        assert!(inst.imus[0].angle_deg.abs() < 1e-9);
        // The rotated raw residual is the bias difference.
        let b = inst.imus[2].bias_difference_dps;
        let b_norm = (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]).sqrt();
        assert!(
            (inst.imus[2].residual_dps - b_norm).abs() < 1e-9,
            "{:?}",
            inst.imus[2]
        );
    }

    #[test]
    fn pyramid_channel_is_the_projection_of_its_own_imu() {
        let m = mounts();
        let trial = synthetic(&m);
        let inst = estimate_installation(&trial).unwrap();
        let geometry = Geometry::from_axes(&[
            [0.62, 0.62, 0.48],
            [-0.62, 0.62, 0.48],
            [-0.62, -0.62, 0.48],
            [0.62, -0.62, 0.48],
        ])
        .unwrap();
        let rows = project_to_pyramid(&trial, &inst, &geometry).unwrap();
        assert_eq!(rows.len(), trial.len());
        let j = 123;
        for (i, mount) in m.iter().enumerate() {
            let h = Vector3::from(geometry.axes()[i]);
            let s = &trial.imus[i].samples[j];
            // In the reference frame, IMU i's vector is R_i ω_i.
            let g = mount * Vector3::from(s.gyro_rps);
            let a = mount * Vector3::from(s.accel_mps2);
            assert!((rows[j].gyro_rps[i] - h.dot(&g)).abs() < 1e-9);
            assert!((rows[j].accel_mps2[i] - h.dot(&a)).abs() < 1e-9);
        }
        assert_eq!(rows[j].gyro_rps[4..], [0.0; MAX_CHANNELS - 4]);
        // The reference IMU's accelerometer, unbiased: channel 0 is exactly h_0 · f_ref.
        let f0 = Vector3::from(trial.imus[0].samples[j].accel_mps2);
        assert!((rows[j].accel_mps2[0] - Vector3::from(geometry.axes()[0]).dot(&f0)).abs() < 1e-12);
    }

    #[test]
    fn stacked_triads_agree_up_to_bias_in_the_common_frame() {
        let trial = synthetic(&mounts());
        let inst = estimate_installation(&trial).unwrap();
        let rows = stack_triads(&trial, &inst).unwrap();
        assert_eq!(rows[0].n, 12);
        for row in rows.iter().step_by(50) {
            for k in 1..4 {
                for axis in 0..3 {
                    // Accelerometers carry no bias here: the triads agree exactly.
                    let d = row.accel_mps2[3 * k + axis] - row.accel_mps2[axis];
                    assert!(d.abs() < 1e-9, "{d}");
                }
            }
        }
        assert_eq!(stacked_axes(2).len(), 6);
        assert!(Geometry::from_axes(&stacked_axes(4)).is_ok());
    }

    #[test]
    fn mismatched_geometry_is_an_error() {
        let trial = synthetic(&mounts()[..3]);
        let inst = estimate_installation(&trial).unwrap();
        let geometry = Geometry::from_axes(&stacked_axes(4)[..4]).unwrap();
        let e = project_to_pyramid(&trial, &inst, &geometry).unwrap_err();
        assert!(e.to_string().contains("4 axes but the trial 3 IMUs"), "{e}");
    }
}
