//! One motion series through the navigator's inertial core with its tilt updates (AHRS), started
//! from the truth at t0 and never told the truth again.
//!
//! The live navigator's own code path: [`AidedNavigator::take_over`] starts it from the state at
//! t0 (the flights start in the air, so static alignment cannot run), then every sample goes
//! through [`AidedNavigator::on_imu`], which predicts the filter and makes the tilt updates of
//! `[navigator.tilt]`. There is no baro, magnetometer or position in these recordings.

use nalgebra::{UnitQuaternion, Vector3};
use rins_navigator::attitude::quaternion_from_euler;
use rins_navigator::ekf::BG;
use rins_navigator::inertial_core::{AidedConfig, AidedNavigator};
use rins_navigator::{ImuBias, NominalState};

use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::run::Start;

/// The solution's attitude over a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AttitudeTrace {
    /// Times, s: t0, then every applied sample after it.
    pub t_s: Vec<f64>,
    /// Body → NED attitude at each time.
    pub attitude: Vec<UnitQuaternion<f64>>,
}

impl AttitudeTrace {
    /// The attitude at `t_s` (spherical interpolation between the neighbouring samples); `None`
    /// outside the trace.
    pub fn at(&self, t_s: f64) -> Option<UnitQuaternion<f64>> {
        let (first, last) = (*self.t_s.first()?, *self.t_s.last()?);
        if !(t_s >= first && t_s <= last) {
            return None;
        }
        let n = self.t_s.len();
        let i = self.t_s.partition_point(|&t| t <= t_s).clamp(1, n) - 1;
        let j = (i + 1).min(n - 1);
        let span = self.t_s[j] - self.t_s[i];
        let f = if span > 0.0 {
            (t_s - self.t_s[i]) / span
        } else {
            0.0
        };
        Some(
            self.attitude[i]
                .try_slerp(&self.attitude[j], f, 1e-12)
                .unwrap_or(self.attitude[i]),
        )
    }
}

/// What is known of the gyro bias at t0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GyroPrior {
    /// Bias estimate, body FRD, rad/s.
    pub bias_rps: [f64; 3],
    /// σ of each axis, rad/s.
    pub sigma_rps: f64,
}

/// One run: the attitude trace and the gyro bias the filter ended with.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AhrsRun {
    /// Attitude over the run.
    pub trace: AttitudeTrace,
    /// The filter's gyro bias estimate at the end, body FRD, rad/s.
    pub final_gyro_bias_rps: [f64; 3],
}

/// Device time of trial time `t_s`, µs: the trial's times start near 0 and may be slightly
/// negative after alignment, so they are moved by a fixed second.
fn device_us(t_s: f64) -> u64 {
    ((t_s + 1.0).max(0.0) * 1e6).round() as u64
}

/// Runs `motion` from `start` through the navigator's inertial core with `config` (its tilt
/// updates included when enabled). The unit's attitude at t0 is the airframe's turned by the
/// inverse of the unit's `mounting` (`C_nav←vehicle = C_nav←unit · mounting`); the gyro bias
/// starts from `prior` when given, else from zero with the configured σ.
pub fn navigate_ahrs(
    motion: &Motion,
    start: &Start,
    config: &AidedConfig,
    mounting: &UnitQuaternion<f64>,
    prior: Option<&GyroPrior>,
) -> AhrsRun {
    let [lat, lon, altitude_zero_m] = config.origin;
    let mut state = NominalState::at_rest(lat, lon, altitude_zero_m + start.height_m);
    let [roll, pitch, heading] = start.euler_rad;
    state.attitude = quaternion_from_euler(roll, pitch, heading) * mounting.inverse();
    state.velocity_ned = Vector3::from(start.velocity_ned);
    let mut bias = ImuBias::default();
    let mut variances = config.noise.initial_variances();
    if let Some(p) = prior {
        bias.gyro_rps = Vector3::from(p.bias_rps);
        variances[BG..BG + 3].fill(p.sigma_rps * p.sigma_rps);
    }
    let mut navigator = AidedNavigator::new(*config);
    navigator.take_over(device_us(start.t_s), state, bias, &variances);
    let mut trace = AttitudeTrace::default();
    trace.t_s.push(start.t_s);
    trace.attitude.push(state.attitude);
    // Sample j is the mean over the interval ending at its time: the first one used is the first
    // after t0.
    let first = ((start.t_s - motion.t0_s) / motion.dt_s).floor().max(-1.0) + 1.0;
    for (j, sample) in motion.samples.iter().enumerate().skip(first as usize) {
        let t_s = motion.time(j);
        let step = navigator.on_imu(device_us(t_s), sample.gyro_rps, sample.accel_mps2, None);
        if !step.propagated.is_some_and(|p| p.is_applied()) {
            continue;
        }
        if let Some(ekf) = navigator.ekf() {
            trace.t_s.push(t_s);
            trace.attitude.push(ekf.state().attitude);
        }
    }
    AhrsRun {
        trace,
        final_gyro_bias_rps: navigator
            .ekf()
            .map_or([0.0; 3], |ekf| ekf.bias().gyro_rps.into()),
    }
}
