//! One motion series through the aided navigator with the simulated receiver's fixes: started
//! from the reference at t0 as `--mode ahrs` starts (the airframe's attitude turned by the
//! series' mounting, the gyro bias from a prior when one is given), the fixes placed by the
//! navigator service's receiver hold, the receiver cut from `gnss_until_s` on. Device time is the
//! trial's time plus a second, as the import writes it.

use ipc_types::GnssFix;
use nalgebra::UnitQuaternion;
use rins_earth::LocalOrigin;
use rins_navigator::NominalState;
use rins_navigator::aiding::gnss::hold::GnssHold;
use rins_navigator::aiding::gnss::measurement::{GnssMeasurement, GnssOutcome};
use rins_navigator::inertial_core::{AidedConfig, AidedNavigator};
use rins_navigator::start::InFlightStart;

use super::receiver::{LocalFix, gnss_fix};
use crate::import::rx_ns;
use crate::quadrotor_ahrs::run::{GyroPrior, device_us, first_sample_after, in_flight_start};
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

/// The navigator settings and `[navigator.start]` of a run: `config` with GNSS aiding on and no
/// receiver delay, its origin moved to the reference's horizontal position at t0 (the start table
/// states a height, not a place), and the start as `--mode ahrs` makes it from `known`, at the
/// reference position's altitude (the receiver's datum: the reference's height above take-off is
/// another one, metres apart).
pub fn gnss_start(
    start: &Start,
    known: &StartKnowledge,
    config: &AidedConfig,
) -> (InFlightStart, AidedConfig) {
    let mut config = *config;
    config.gnss.enabled = true;
    config.gnss.delay_s = 0.0;
    let [lat0, lon0, alt0] = config.origin;
    let [lat, lon, _] =
        LocalOrigin::new(lat0, lon0, alt0).geodetic([start.ned_m[0], start.ned_m[1], 0.0]);
    // As a configuration states it (degrees), so that the running navigator has the same origin.
    let stated = |rad: f64| rad.to_degrees().to_radians();
    config.origin = [stated(lat), stated(lon), alt0];
    let (mut table, config) =
        in_flight_start(start, &config, &known.mounting, known.prior.as_ref());
    table.altitude_m = alt0 - start.ned_m[2];
    (table, config)
}

/// The receiver's messages of the epochs of `fixes` after `from_s` and before `until_s`, about
/// `origin`, numbered from 1 in the epochs' order.
pub fn receiver_messages(
    fixes: &[LocalFix],
    origin: &LocalOrigin,
    from_s: f64,
    until_s: f64,
) -> Vec<GnssFix> {
    fixes
        .iter()
        .enumerate()
        .filter(|(_, f)| f.t_s > from_s && f.t_s < until_s)
        .map(|(k, f)| gnss_fix(f, origin, k as u64 + 1))
        .collect()
}

/// Runs `motion` from `start` with `fixes` (those at or after `gnss_until_s` withheld) through an
/// [`AidedNavigator`] with `config` as the navigator service runs it: started from the table
/// [`gnss_start`] makes, each fix made a receiver message ([`super::receiver::gnss_fix`]) received
/// at its device time, held and placed by the service's own receiver hold. Fixes and scores stay
/// in the reference's local frame (`config.origin`).
pub fn navigate_with_gnss(
    motion: &Motion,
    start: &Start,
    known: &StartKnowledge,
    config: &AidedConfig,
    fixes: &[LocalFix],
    gnss_until_s: f64,
) -> GnssTrace {
    let [lat0, lon0, alt0] = config.origin;
    let origin = LocalOrigin::new(lat0, lon0, alt0);
    let to_local = |s: &NominalState| {
        let [n, e, _] = origin.ned(s.lat, s.lon, s.alt);
        [n, e]
    };
    let (table, config) = gnss_start(start, known, config);
    let s = table.state(&config);
    let mut nav = AidedNavigator::new(config);
    nav.take_over(s.device_time_us, s.state, s.bias, &s.variances);
    let messages = receiver_messages(fixes, &origin, start.t_s, gnss_until_s);
    let mut hold = GnssHold::new(config.gnss.delay_s);
    let mut next_fix = 0;
    let mut trace = GnssTrace::default();
    for (j, sample) in motion
        .samples
        .iter()
        .enumerate()
        .skip(first_sample_after(motion, start.t_s))
    {
        let t_s = motion.time(j);
        let (imu_us, imu_rx) = (device_us(t_s), rx_ns(device_us(t_s)));
        // What the service has received by this frame, then what this frame releases.
        while let Some(fix) = messages
            .get(next_fix)
            .filter(|f| f.header.origin_rx_ns <= imu_rx)
        {
            hold.push(*fix);
            next_fix += 1;
        }
        hold.release(imu_us, imu_rx, |fix, t_us| {
            match nav.on_gnss(&GnssMeasurement::from_fix(fix, t_us)) {
                GnssOutcome::Applied { .. } | GnssOutcome::Readmitted => trace.applied += 1,
                GnssOutcome::Outlier => trace.outliers += 1,
                GnssOutcome::Rejected => trace.rejected += 1,
                _ => {}
            }
        });
        let step = nav.on_imu(imu_us, sample.gyro_rps, sample.accel_mps2, None);
        if !step.propagated.is_some_and(|p| p.is_applied()) {
            continue;
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
