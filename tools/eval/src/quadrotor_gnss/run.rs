//! One motion series through the aided navigator with the simulated receiver's fixes: started
//! from the reference at t0 as `--mode ahrs` starts (the airframe's attitude turned by the
//! series' mounting, the gyro bias from a prior when one is given), the fixes applied at their
//! own time, the receiver cut from `gnss_until_s` on.

use nalgebra::{UnitQuaternion, Vector3};
use rins_earth::LocalOrigin;
use rins_navigator::aiding::gnss::measurement::{GnssMeasurement, GnssOutcome};
use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::inertial_core::AidedNavigator;
use rins_navigator::mechanisation::quaternion_from_euler;
use rins_navigator::{ImuBias, NominalState};

use super::receiver::{LocalFix, SIGMA_H_M, SIGMA_V_M, SIGMA_VEL_MPS};
use crate::quadrotor_ahrs::run::GyroPrior;
use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::run::Start;

/// The navigator's state at one instant, in the reference's local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time on the trial's time base, s.
    pub t_s: f64,
    /// Roll, pitch, yaw, rad.
    pub euler_rad: [f64; 3],
    /// North and east of the reference's first row, m.
    pub north_east_m: [f64; 2],
}

/// A run: the navigator's samples and what became of the fixes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct GnssTrace {
    /// Every propagated sample.
    pub samples: Vec<Sample>,
    /// Fixes applied.
    pub applied: usize,
    /// Fixes outside the gate.
    pub outliers: usize,
    /// Fixes skipped because the receiver was judged inconsistent, and times it was.
    pub rejected: usize,
    /// Times the monitor rejected the receiver.
    pub rejections: u64,
    /// The filter's gyro bias estimate at the end, body FRD, rad/s.
    pub final_gyro_bias_rps: [f64; 3],
}

/// How a run starts besides the reference's state at t0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StartKnowledge {
    /// The series' mounting on the airframe (`C_nav←vehicle = C_nav←unit · mounting`).
    pub mounting: UnitQuaternion<f64>,
    /// The gyro bias at t0; zero with the configured σ when absent.
    pub prior: Option<GyroPrior>,
}

impl Default for StartKnowledge {
    fn default() -> Self {
        Self {
            mounting: UnitQuaternion::identity(),
            prior: None,
        }
    }
}

/// Runs `motion` from `start` with `fixes` (those at or after `gnss_until_s` withheld) through an
/// [`AidedNavigator`] with `config` (GNSS aiding turned on). Device time counts from t0.
pub fn navigate_with_gnss(
    motion: &Motion,
    start: &Start,
    known: &StartKnowledge,
    config: &AidedConfig,
    fixes: &[LocalFix],
    gnss_until_s: f64,
) -> GnssTrace {
    let mut config = *config;
    config.gnss.enabled = true;
    config.gnss.delay_s = 0.0;
    let mut bias = ImuBias::default();
    if let Some(p) = &known.prior {
        config.noise.initial_gyro_bias_sigma = p.sigma_rps;
        bias.gyro_rps = Vector3::from(p.bias_rps);
    }
    let [lat0, lon0, alt0] = config.origin;
    let origin = LocalOrigin::new(lat0, lon0, alt0);
    let to_geo = |ned: [f64; 3]| origin.geodetic(ned);
    let to_local = |s: &NominalState| {
        let [n, e, _] = origin.ned(s.lat, s.lon, s.alt);
        [n, e]
    };
    // Device time: µs since one second before t0, so that every time is positive.
    let us = |t_s: f64| ((t_s - start.t_s + 1.0) * 1e6).round().max(0.0) as u64;

    let mut nav = AidedNavigator::new(config);
    let [roll, pitch, heading] = start.euler_rad;
    let [lat, lon, alt] = to_geo(start.ned_m);
    let mut state = NominalState::at_rest(lat, lon, alt);
    state.attitude = quaternion_from_euler(roll, pitch, heading) * known.mounting.inverse();
    state.velocity_ned = Vector3::from(start.velocity_ned);
    nav.take_over(
        us(start.t_s),
        state,
        bias,
        &config.noise.initial_variances(),
    );

    let mut trace = GnssTrace::default();
    let mut next_fix = fixes.partition_point(|f| f.t_s <= start.t_s);
    let first = ((start.t_s - motion.t0_s) / motion.dt_s).floor().max(-1.0) + 1.0;
    for (j, sample) in motion.samples.iter().enumerate().skip(first as usize) {
        let t_s = motion.time(j);
        let step = nav.on_imu(us(t_s), sample.gyro_rps, sample.accel_mps2, None);
        if !step.propagated.is_some_and(|p| p.is_applied()) {
            continue;
        }
        while let Some(fix) = fixes.get(next_fix).filter(|f| f.t_s <= t_s) {
            next_fix += 1;
            if fix.t_s >= gnss_until_s {
                continue;
            }
            let m = GnssMeasurement {
                t_us: us(fix.t_s),
                receiver_time_us: us(fix.t_s),
                fix_3d: true,
                position: to_geo(fix.ned_m),
                velocity_ned: Some(fix.velocity_ned_mps),
                sigma_h_m: SIGMA_H_M,
                sigma_v_m: SIGMA_V_M,
                sigma_vel_mps: SIGMA_VEL_MPS,
            };
            match nav.on_gnss(&m) {
                GnssOutcome::Applied { .. } | GnssOutcome::Readmitted => trace.applied += 1,
                GnssOutcome::Outlier => trace.outliers += 1,
                GnssOutcome::Rejected => trace.rejected += 1,
                _ => {}
            }
        }
        if let Some(ekf) = nav.ekf() {
            trace.samples.push(Sample {
                t_s,
                euler_rad: ekf.state().euler(),
                north_east_m: to_local(ekf.state()),
            });
        }
    }
    trace.rejections = nav.gnss_monitor().rejections();
    trace.final_gyro_bias_rps = nav.ekf().map_or([0.0; 3], |ekf| ekf.bias().gyro_rps.into());
    trace
}
