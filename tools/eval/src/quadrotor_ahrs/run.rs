//! One motion series through the navigator's inertial core with its tilt updates (AHRS), started
//! from the truth at t0 and never told the truth again.
//!
//! The live navigator's own code path: [`AidedNavigator::take_over`] starts it from the state at
//! t0 built by the navigator's in-flight start ([`InFlightStart`]; the flights start in the air,
//! so static alignment cannot run), then every sample goes
//! through [`AidedNavigator::on_imu`], which predicts the filter and makes the tilt updates of
//! `[navigator.tilt]`. There is no baro, magnetometer or position in these recordings.

use nalgebra::UnitQuaternion;
use rins_navigator::attitude::{euler_from_quaternion, quaternion_from_euler};
use rins_navigator::ekf::ATT;
use rins_navigator::inertial_core::{AidedConfig, AidedNavigator};
use rins_navigator::start::InFlightStart;

use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::run::Start;

/// The solution's attitude over a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AttitudeTrace {
    /// Times, s: t0, then every applied sample after it.
    pub t_s: Vec<f64>,
    /// Body → NED attitude at each time.
    pub attitude: Vec<UnitQuaternion<f64>>,
    /// The filter's σ of its tilt (the horizontal attitude error, both axes together) at each
    /// time, rad; empty where the source gives none (the units' own filters, a live run).
    pub tilt_sigma_rad: Vec<f64>,
}

impl AttitudeTrace {
    /// The filter's tilt σ at `t_s`: that of the last entry at or before it, rad; `None` outside
    /// the trace or without σ.
    pub fn tilt_sigma_at(&self, t_s: f64) -> Option<f64> {
        let i = self.t_s.partition_point(|&t| t <= t_s).checked_sub(1)?;
        self.tilt_sigma_rad.get(i).copied()
    }

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

/// Device time of trial time `t_s`, s: the trial's times start near 0 and may be slightly
/// negative after alignment, so they are moved by a fixed second.
pub fn device_time_s(t_s: f64) -> f64 {
    t_s + 1.0
}

/// Device time of trial time `t_s`, µs (as [`InFlightStart::device_time_us`] rounds it).
pub fn device_us(t_s: f64) -> u64 {
    (device_time_s(t_s).max(0.0) * 1e6).round() as u64
}

/// The navigator's in-flight start of a run (`[navigator.start]`) and the settings it runs with:
/// the airframe's attitude at t0 turned by the inverse of the unit's `mounting`
/// (`C_nav←vehicle = C_nav←unit · mounting`), the velocity and height at t0, and the gyro bias
/// from `prior` when given (its σ then replaces `initial_gyro_bias_sigma`), else zero with the
/// configured σ. The running navigator takes the same table over.
pub fn in_flight_start(
    start: &Start,
    config: &AidedConfig,
    mounting: &UnitQuaternion<f64>,
    prior: Option<&GyroPrior>,
) -> (InFlightStart, AidedConfig) {
    let [roll, pitch, heading] = start.euler_rad;
    let attitude = quaternion_from_euler(roll, pitch, heading) * mounting.inverse();
    let [roll, pitch, heading] = euler_from_quaternion(&attitude);
    let mut config = *config;
    // A start states the position: the running navigator then counts it known.
    config.origin_known = true;
    if let Some(p) = prior {
        config.noise.initial_gyro_bias_sigma = p.sigma_rps;
    }
    let table = InFlightStart {
        time_s: device_time_s(start.t_s),
        roll_deg: roll.to_degrees(),
        pitch_deg: pitch.to_degrees(),
        heading_deg: heading.to_degrees(),
        velocity_ned_mps: start.velocity_ned,
        altitude_m: config.origin[2] + start.height_m,
        gyro_bias_dps: prior.map(|p| p.bias_rps.map(f64::to_degrees)),
    };
    (table, config)
}

/// Index of the first sample of `motion` after the start time `t_s`: sample j is the mean over
/// the interval ending at its time.
pub fn first_sample_after(motion: &Motion, t_s: f64) -> usize {
    (((t_s - motion.t0_s) / motion.dt_s).floor().max(-1.0) + 1.0) as usize
}

/// Runs `motion` from `start` through the navigator's inertial core with `config` (its tilt
/// updates included when enabled), started as [`in_flight_start`] says.
pub fn navigate_ahrs(
    motion: &Motion,
    start: &Start,
    config: &AidedConfig,
    mounting: &UnitQuaternion<f64>,
    prior: Option<&GyroPrior>,
) -> AhrsRun {
    let (table, config) = in_flight_start(start, config, mounting, prior);
    let s = table.state(&config);
    let mut navigator = AidedNavigator::new(config);
    navigator.take_over(s.device_time_us, s.state, s.bias, &s.variances);
    let mut trace = AttitudeTrace::default();
    trace.t_s.push(start.t_s);
    trace.attitude.push(s.state.attitude);
    trace
        .tilt_sigma_rad
        .push((s.variances[ATT] + s.variances[ATT + 1]).sqrt());
    let first = first_sample_after(motion, start.t_s);
    for (j, sample) in motion.samples.iter().enumerate().skip(first) {
        let t_s = motion.time(j);
        let step = navigator.on_imu(device_us(t_s), sample.gyro_rps, sample.accel_mps2, None);
        if !step.propagated.is_some_and(|p| p.is_applied()) {
            continue;
        }
        if let Some(ekf) = navigator.ekf() {
            trace.t_s.push(t_s);
            trace.attitude.push(ekf.state().attitude);
            trace
                .tilt_sigma_rad
                .push(ekf.sigma(ATT).hypot(ekf.sigma(ATT + 1)));
        }
    }
    AhrsRun {
        trace,
        final_gyro_bias_rps: navigator
            .ekf()
            .map_or([0.0; 3], |ekf| ekf.bias().gyro_rps.into()),
    }
}
