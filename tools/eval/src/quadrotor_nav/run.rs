//! One motion series through the navigator's error-state filter, started from the truth.
//!
//! The flights start in the air, so the navigator's static alignment cannot run; the filter is
//! started instead from the truth at one instant t0 and then only predicted (no aiding: no baro,
//! no magnetometer, no zero-velocity updates), which is the navigator's free-inertial path.

use nalgebra::Vector3;
use rins_navigator::ekf::ErrorStateEkf;
use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::mechanisation::quaternion_from_euler;
use rins_navigator::{ImuBias, NominalState};

use super::frames::Motion;
use crate::datasets::quadrotor::TruthRow;

/// The state the filter starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Start {
    /// Index of the truth row at t0.
    pub row: usize,
    /// t0 on the trial's time base, s.
    pub t_s: f64,
    /// Vehicle roll, pitch, heading (ZYX, FRD body → NED), rad.
    pub euler_rad: [f64; 3],
    /// Velocity, NED, m/s.
    pub velocity_ned: [f64; 3],
    /// Height above take-off, m.
    pub height_m: f64,
    /// North, east, down from the reference's first row, m.
    pub ned_m: [f64; 3],
}

/// The start at the first truth row inside `[from_s, to_s]` that has a row on either side: the
/// attitude and height are that row's, the velocity the central difference of the north, east
/// and down positions of its neighbours (the truth has no velocity column; the central difference
/// is the velocity at t0 itself, not half a row earlier or later). `None` when no row qualifies.
pub fn start_from_truth(truth: &[TruthRow], from_s: f64, to_s: f64) -> Option<Start> {
    let row = (1..truth.len().saturating_sub(1))
        .find(|&i| truth[i].t_s >= from_s && truth[i].t_s <= to_s)?;
    let (before, at, after) = (&truth[row - 1], &truth[row], &truth[row + 1]);
    let span = after.t_s - before.t_s;
    if !span.is_finite() || span <= 0.0 {
        return None;
    }
    Some(Start {
        row,
        t_s: at.t_s,
        euler_rad: [at.roll_rad, at.pitch_rad, at.heading_rad],
        velocity_ned: [
            (after.north_m - before.north_m) / span,
            (after.east_m - before.east_m) / span,
            (after.down_m - before.down_m) / span,
        ],
        height_m: at.height_m,
        ned_m: [at.north_m, at.east_m, at.down_m],
    })
}

/// The navigator's roll, pitch and height over a run, from t0 on.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Trace {
    /// Times, s: t0, then every sample after it.
    pub t_s: Vec<f64>,
    /// Roll at each time, rad (body FRD relative to NED).
    pub roll_rad: Vec<f64>,
    /// Pitch at each time, rad.
    pub pitch_rad: Vec<f64>,
    /// Height above take-off, m.
    pub height_m: Vec<f64>,
    /// Samples the filter did not apply (non-finite input).
    pub skipped: usize,
}

impl Trace {
    fn push(&mut self, t_s: f64, state: &NominalState, altitude_zero_m: f64) {
        let [roll, pitch, _] = state.euler();
        self.t_s.push(t_s);
        self.roll_rad.push(roll);
        self.pitch_rad.push(pitch);
        self.height_m.push(state.alt - altitude_zero_m);
    }
}

/// Runs `motion` from `start` through a filter made from the profile's strapdown and noise
/// settings, at the profile's origin (latitude for gravity; the take-off point at the origin's
/// altitude). No gyro bias is subtracted: the recordings start in flight, so there is no rest
/// interval to measure one on, and the truth is not used after t0.
pub fn navigate(motion: &Motion, start: &Start, config: &AidedConfig) -> Trace {
    let [lat, lon, altitude_zero_m] = config.origin;
    let mut state = NominalState::at_rest(lat, lon, altitude_zero_m + start.height_m);
    let [roll, pitch, heading] = start.euler_rad;
    state.attitude = quaternion_from_euler(roll, pitch, heading);
    state.velocity_ned = Vector3::from(start.velocity_ned);
    let mut ekf = ErrorStateEkf::new(state, ImuBias::default(), config.strapdown, config.noise);
    let mut trace = Trace::default();
    trace.push(start.t_s, ekf.state(), altitude_zero_m);
    // Sample j is the mean over the interval ending at its time: the first one used is the first
    // after t0, over the part of its interval after t0.
    let first = ((start.t_s - motion.t0_s) / motion.dt_s).floor().max(-1.0) + 1.0;
    let mut previous_s = start.t_s;
    for (j, sample) in motion.samples.iter().enumerate().skip(first as usize) {
        let t_s = motion.time(j);
        let dt_s = t_s - previous_s;
        if dt_s <= 0.0 {
            continue;
        }
        previous_s = t_s;
        if !ekf
            .predict(sample.gyro_rps, sample.accel_mps2, dt_s)
            .is_applied()
        {
            trace.skipped += 1;
            continue;
        }
        trace.push(t_s, ekf.state(), altitude_zero_m);
    }
    trace
}
