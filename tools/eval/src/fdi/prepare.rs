//! Pre-processing of one trial into the fuser's counts (see the module docs of [`super`]).

use anyhow::{Result, anyhow};
use rins_fusion::fdi::channel_health::COUNT_MAX;
use rins_fusion::{Geometry, WlsSolver};

use super::layout::{Layout, Sensor};
use super::learned_geometry::LearnedGeometry;
use super::{BIAS_WINDOW_S, PREFILTER_ROWS};
use crate::datasets::quadrotor::lever_arm::remove_lever_arms;
use crate::datasets::quadrotor::projection::{
    ChannelRow, MAX_CHANNELS, project_to_pyramid, stack_triads,
};
use crate::datasets::quadrotor::{IMU_RATE_HZ, Trial};

/// One trial's channels ready for the fuser.
pub(crate) struct Prepared {
    /// Counts per row, gyro then accel.
    pub gyro: Vec<[i16; MAX_CHANNELS]>,
    pub accel: Vec<[i16; MAX_CHANNELS]>,
    pub n: usize,
    /// Channel-sample pairs at a converter rail in the data itself (genuine over-range).
    pub clipped: usize,
    /// Per-trial parity estimate of the channel σ (for the fit), SI.
    pub sigma_hat: [f64; 2],
    /// Relative biases removed, SI (largest magnitude per type).
    pub max_bias_removed: [f64; 2],
}

fn to_counts(z: f64, lsb: f64) -> (i16, bool) {
    let c = (z / lsb).round();
    let lo = f64::from(rins_fusion::fdi::channel_health::COUNT_MIN);
    let hi = f64::from(COUNT_MAX);
    (c.clamp(lo, hi) as i16, !(lo < c && c < hi))
}

/// Estimates each channel's σ from the parity of the trial (equal σ assumed): with unit
/// variances, `T = |V_w z|²` has mean m·σ² for white channel noise.
fn parity_sigma(geometry: &Geometry, rows: &[[f64; MAX_CHANNELS]]) -> f64 {
    let n = geometry.n();
    let Ok(space) = rins_fusion::ParitySpace::new(geometry, geometry.full_mask(), &vec![1.0; n])
    else {
        return f64::NAN;
    };
    let m = space.dimension().max(1) as f64;
    let mut pw = [0.0; rins_fusion::fdi::MAX_PARITY];
    let mean_t = rows
        .iter()
        .map(|z| space.whitened_parity(z, &mut pw))
        .sum::<f64>()
        / rows.len().max(1) as f64;
    (mean_t / m).sqrt()
}

/// Relative-bias removal (see the module docs) on one sensor type's channels.
fn remove_relative_bias(geometry: &Geometry, rows: &mut [[f64; MAX_CHANNELS]]) -> Result<f64> {
    let n = geometry.n();
    let window = ((BIAS_WINDOW_S * IMU_RATE_HZ) as usize)
        .min(rows.len())
        .max(1);
    let mut mean = [0.0; MAX_CHANNELS];
    for z in &rows[..window] {
        for i in 0..n {
            mean[i] += z[i] / window as f64;
        }
    }
    let solver = WlsSolver::new(geometry, geometry.full_mask(), &vec![1.0; n])
        .map_err(|e| anyhow!("least squares over the evaluation geometry: {e}"))?;
    let (x, _) = solver.solve(&mean);
    let mut bias = [0.0; MAX_CHANNELS];
    let mut largest: f64 = 0.0;
    for (i, h) in geometry.axes().iter().enumerate() {
        bias[i] = mean[i] - (h[0] * x[0] + h[1] * x[1] + h[2] * x[2]);
        largest = largest.max(bias[i].abs());
    }
    for z in rows.iter_mut() {
        for i in 0..n {
            z[i] -= bias[i];
        }
    }
    Ok(largest)
}

/// The trial's channels in `layout`, with the installation and lever arms of `learned` (from
/// the other flights).
pub(crate) fn prepare(
    trial: &Trial,
    layout: Layout,
    geometry: &Geometry,
    lsb: [f64; 2],
    learned: &LearnedGeometry,
) -> Result<Prepared> {
    let installation = &learned.installation;
    let mut trial = trial.clone();
    remove_lever_arms(&mut trial, installation, &learned.arms, IMU_RATE_HZ);
    let trial = &trial;
    let rows: Vec<ChannelRow> = match layout {
        Layout::Pyramid4 => project_to_pyramid(trial, installation, geometry)?,
        Layout::Stacked { .. } => stack_triads(trial, installation)?,
    };
    let n = geometry.n();
    let mut out = Prepared {
        gyro: Vec::with_capacity(rows.len()),
        accel: Vec::with_capacity(rows.len()),
        n,
        clipped: 0,
        sigma_hat: [0.0; 2],
        max_bias_removed: [0.0; 2],
    };
    for (k, sensor) in Sensor::ALL.into_iter().enumerate() {
        let mut z: Vec<[f64; MAX_CHANNELS]> = rows
            .iter()
            .map(|r| match sensor {
                Sensor::Gyro => r.gyro_rps,
                Sensor::Accel => r.accel_mps2,
            })
            .collect();
        let smooth = PREFILTER_ROWS;
        if smooth > 1 {
            let src = z.clone();
            for (j, row) in z.iter_mut().enumerate() {
                let from = j.saturating_sub(smooth - 1);
                let w = (j - from + 1) as f64;
                for i in 0..n {
                    row[i] = src[from..=j].iter().map(|r| r[i]).sum::<f64>() / w;
                }
            }
        }
        out.max_bias_removed[k] = remove_relative_bias(geometry, &mut z)?;
        out.sigma_hat[k] = parity_sigma(geometry, &z);
        let counts: Vec<[i16; MAX_CHANNELS]> = z
            .iter()
            .map(|row| {
                let mut c = [0i16; MAX_CHANNELS];
                for i in 0..n {
                    let (v, clipped) = to_counts(row[i], lsb[k]);
                    c[i] = v;
                    out.clipped += usize::from(clipped);
                }
                c
            })
            .collect();
        match sensor {
            Sensor::Gyro => out.gyro = counts,
            Sensor::Accel => out.accel = counts,
        }
    }
    Ok(out)
}
