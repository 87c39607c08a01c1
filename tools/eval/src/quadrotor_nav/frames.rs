//! The motion each navigator run sees: rate and specific force in the vehicle's body frame (FRD).
//!
//! The truth's roll and pitch are the airframe's, so every run must navigate the airframe, not a
//! unit. The installation estimate ([`estimate_installation`]) gives each unit's rotation into
//! the reference unit's frame (IMU_1), from the gyro data alone; the reference's own rotation
//! into the vehicle frame is a separate input, `vehicle_from_reference` (see
//! [`super::vehicle_from_reference`] for the value used on the recordings).
//!
//! The fused run takes the four triads stacked in the vehicle frame (12 channels) through the
//! fusion library's least squares with equal weights. With equal weights that is the mean of the
//! units: the rate is the body's (the same at every point of a rigid body), the specific force
//! is the one at the units' centroid (the lever-arm terms `K(t) r_k` average to `K(t) r̄`), so no
//! lever-arm correction is needed and none of one unit's errors is traded for another's.
//!
//! [`estimate_installation`]: crate::datasets::quadrotor::projection::estimate_installation

use anyhow::{Result, anyhow};
use nalgebra::{Rotation3, Vector3};
use rins_fusion::{Geometry, WlsSolver};

use crate::datasets::quadrotor::projection::{Installation, stack_triads, stacked_axes};
use crate::datasets::quadrotor::{IMU_RATE_HZ, Trial};

/// One sample of body motion, vehicle frame (FRD).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodySample {
    /// Rate, rad/s.
    pub gyro_rps: [f64; 3],
    /// Specific force, m/s².
    pub accel_mps2: [f64; 3],
}

/// Uniformly sampled body motion. Row j is at `t0_s + j · dt_s`: the loader keeps the data on
/// the row grid even where a file repeats or skips a timestamp, so the grid, not the time
/// column, is the sampling instant.
#[derive(Debug, Clone, PartialEq)]
pub struct Motion {
    /// Time of row 0 on the trial's time base, s.
    pub t0_s: f64,
    /// Sample period, s.
    pub dt_s: f64,
    /// One body-frame sample per row, in row order.
    pub samples: Vec<BodySample>,
}

impl Motion {
    /// Time of row `j`, s.
    pub fn time(&self, j: usize) -> f64 {
        self.t0_s + j as f64 * self.dt_s
    }

    /// Time of the last row (`t0_s` when empty), s.
    pub fn end_s(&self) -> f64 {
        self.time(self.samples.len().saturating_sub(1))
    }
}

fn t0(trial: &Trial) -> f64 {
    trial
        .imus
        .first()
        .and_then(|s| s.samples.first())
        .map_or(0.0, |s| s.t_s)
}

fn turn(r: &Rotation3<f64>, v: [f64; 3]) -> [f64; 3] {
    (r * Vector3::from(v)).into()
}

/// Unit `index` (position in `trial.imus`) alone, turned into the vehicle frame.
pub fn single(
    trial: &Trial,
    installation: &Installation,
    vehicle_from_reference: &Rotation3<f64>,
    index: usize,
) -> Result<Motion> {
    let (Some(series), Some(inst)) = (trial.imus.get(index), installation.imus.get(index)) else {
        return Err(anyhow!("{}: no IMU at position {index}", trial.name));
    };
    if series.imu != inst.imu {
        return Err(anyhow!(
            "{}: installation of IMU_{} given for IMU_{}",
            trial.name,
            inst.imu,
            series.imu
        ));
    }
    let r = vehicle_from_reference * inst.rotation;
    Ok(Motion {
        t0_s: t0(trial),
        dt_s: 1.0 / IMU_RATE_HZ,
        samples: series
            .samples
            .iter()
            .map(|s| BodySample {
                gyro_rps: turn(&r, s.gyro_rps),
                accel_mps2: turn(&r, s.accel_mps2),
            })
            .collect(),
    })
}

/// Every unit of the trial combined by equal-weight least squares over the stacked triads, in
/// the vehicle frame.
pub fn fused(
    trial: &Trial,
    installation: &Installation,
    vehicle_from_reference: &Rotation3<f64>,
) -> Result<Motion> {
    let rows = stack_triads(trial, installation)?;
    let axes = stacked_axes(trial.imus.len());
    let geometry =
        Geometry::from_axes(&axes).map_err(|e| anyhow!("{}: stacked geometry: {e}", trial.name))?;
    let solver = WlsSolver::new(&geometry, geometry.full_mask(), &vec![1.0; geometry.n()])
        .map_err(|e| anyhow!("{}: least squares over the stacked triads: {e}", trial.name))?;
    Ok(Motion {
        t0_s: t0(trial),
        dt_s: 1.0 / IMU_RATE_HZ,
        samples: rows
            .iter()
            .map(|row| {
                let (gyro, _) = solver.solve(&row.gyro_rps[..row.n]);
                let (accel, _) = solver.solve(&row.accel_mps2[..row.n]);
                BodySample {
                    gyro_rps: turn(vehicle_from_reference, gyro),
                    accel_mps2: turn(vehicle_from_reference, accel),
                }
            })
            .collect(),
    })
}
