//! GNSS aiding: the delayed measurement against closed form, the lever arm, the corrections a
//! remembered state receives, and the consistency monitor on a jump and on a slow drift.

use nalgebra::Vector3;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rins_earth::{meridian_radius, prime_vertical_radius};
use rins_navigator::aiding::gnss::config::GnssAidingConfig;
use rins_navigator::aiding::gnss::measurement::{GnssMeasurement, GnssOutcome};
use rins_navigator::aiding::gnss::monitor::RejectReason;
use rins_navigator::ekf::gnss::{antenna_position, antenna_velocity};
use rins_navigator::ekf::{EkfNoise, ErrorStateEkf};
use rins_navigator::inertial_core::AidedNavigator;
use rins_navigator::mechanisation::quaternion_from_euler;
use rins_navigator::state_history::{PastState, StateHistory};
use rins_navigator::{ImuBias, NavigatorConfig, NominalState, StrapdownConfig};

const LAT: f64 = 0.8;
const ALT: f64 = 100.0;
const SPEED: f64 = 10.0;

/// A filter moving north at `SPEED`, level, heading north, from (LAT, 0, ALT).
fn moving_filter() -> ErrorStateEkf {
    let mut state = NominalState::at_rest(LAT, 0.0, ALT);
    state.velocity_ned = Vector3::new(SPEED, 0.0, 0.0);
    ErrorStateEkf::new(
        state,
        ImuBias::default(),
        StrapdownConfig::default(),
        EkfNoise::default(),
    )
}

/// Latitude `metres` north of LAT.
fn lat_north(metres: f64) -> f64 {
    LAT + metres / (meridian_radius(LAT) + ALT)
}

/// Propagates `ekf` at 1 kHz for `seconds`, level and unaccelerated, recording `history`.
fn cruise(ekf: &mut ErrorStateEkf, history: &mut StateHistory, t0_us: u64, seconds: f64) -> u64 {
    let g = ekf.strapdown().gravity();
    let mut t_us = t0_us;
    for _ in 0..(seconds * 1000.0).round() as u64 {
        t_us += 1_000;
        assert!(ekf.predict([0.0; 3], [0.0, 0.0, -g], 1e-3).is_applied());
        history.record(t_us, ekf, Vector3::zeros());
    }
    t_us
}

#[test]
fn a_fix_measured_100_ms_ago_agrees_with_the_state_of_its_instant_not_the_present() {
    let mut ekf = moving_filter();
    let mut history = StateHistory::default();
    history.record(0, &ekf, Vector3::zeros());
    let now_us = cruise(&mut ekf, &mut history, 0, 1.0);
    // The truth: 10 m/s north from the start, so the antenna was 9 m north at 0.9 s.
    let measured = [lat_north(9.0), 0.0, ALT];
    let arm = Vector3::zeros();
    let past = history
        .at(now_us - 100_000, ekf.corrections())
        .expect("in history");
    let delayed = antenna_position(&past, measured, &arm, 1.0, 1.0);
    assert!(delayed.innovation.norm() < 1e-3, "{}", delayed.innovation);
    // Against the present the fix looks 1 m (the motion over 100 ms) behind.
    let present = antenna_position(
        &PastState::now(&ekf, Vector3::zeros()),
        measured,
        &arm,
        1.0,
        1.0,
    );
    assert!((present.innovation.x + SPEED * 0.1).abs() < 1e-3);
}

#[test]
fn a_remembered_state_receives_the_corrections_made_after_it() {
    let mut ekf = moving_filter();
    let mut history = StateHistory::default();
    history.record(0, &ekf, Vector3::zeros());
    let t1 = cruise(&mut ekf, &mut history, 0, 0.5);
    let before = history.at(t1 - 200_000, ekf.corrections()).expect("held");
    // A precise fix 2 m north of where the filter is now, and 0.4 m/s faster (a measured
    // velocity): both corrections move the remembered state too.
    let now = PastState::now(&ekf, Vector3::zeros());
    let north = now.ned_to(now.lat, now.lon, now.alt).x;
    assert!(north.abs() < 1e-9);
    let fix = antenna_position(
        &now,
        [lat_north(SPEED * 0.5 + 2.0), 0.0, ALT],
        &Vector3::zeros(),
        0.01,
        0.01,
    );
    let _ = ekf.update(
        rins_navigator::ekf::AidingSource::Gnss,
        &fix.h,
        &fix.innovation,
        &fix.r,
        f64::INFINITY,
    );
    let applied = *ekf.corrections();
    let after = history.at(t1 - 200_000, ekf.corrections()).expect("held");
    let moved = before.ned_to(after.lat, after.lon, after.alt);
    // The remembered state moves by the position correction less what the velocity correction
    // says its error was 0.2 s earlier.
    let dp = applied.position_ned_m.x;
    let dv = applied.velocity_ned_mps.x;
    assert!(dp > 1.9, "the position was corrected by {dp} m");
    assert!(
        (moved.x - (dp - dv * 0.2)).abs() < 1e-6,
        "{moved} vs {dp}, {dv}"
    );
    assert!((after.velocity_ned.x - before.velocity_ned.x - dv).abs() < 1e-12);
}

#[test]
fn the_lever_arm_is_turned_with_the_attitude_and_its_rotation_adds_velocity() {
    let mut state = NominalState::at_rest(LAT, 0.0, ALT);
    state.attitude = quaternion_from_euler(0.0, 0.0, std::f64::consts::FRAC_PI_2);
    let ekf = ErrorStateEkf::new(
        state,
        ImuBias::default(),
        StrapdownConfig::default(),
        EkfNoise::default(),
    );
    // Heading east: an antenna 1 m forward is 1 m east; turning at 0.5 rad/s about z it moves
    // 0.5 m/s to the right of the nose, south.
    let rate = Vector3::new(0.0, 0.0, 0.5);
    let past = PastState::now(&ekf, rate);
    let arm = Vector3::new(1.0, 0.0, 0.0);
    let east = 1.0 / ((prime_vertical_radius(LAT) + ALT) * LAT.cos());
    let p = antenna_position(&past, [LAT, east, ALT], &arm, 1.0, 1.0);
    assert!(p.innovation.norm() < 1e-6, "{}", p.innovation);
    let v = antenna_velocity(&past, [-0.5, 0.0, 0.0], &arm, 0.1);
    assert!(v.innovation.norm() < 1e-9, "{}", v.innovation);
}

/// A navigator hovering at (LAT, 0, ALT) with a perfect IMU, GNSS aiding on, running `seconds`
/// of 1 kHz IMU with a fix every 0.2 s from `fix_at(t_s)`; returns the outcomes and the largest
/// step of the horizontal position between samples after the first 20 s.
fn hover(
    seconds: f64,
    fix_at: impl Fn(f64) -> [f64; 2],
) -> (AidedNavigator, Vec<(f64, GnssOutcome)>, f64) {
    let mut config = NavigatorConfig {
        initial_latitude_deg: Some(LAT.to_degrees()),
        initial_longitude_deg: Some(0.0),
        initial_altitude_m: ALT,
        ..NavigatorConfig::default()
    };
    config.gnss = GnssAidingConfig {
        enabled: true,
        ..GnssAidingConfig::default()
    };
    config.baro.enabled = false;
    config.mag.enabled = false;
    let aided = config.aided_config();
    let mut nav = AidedNavigator::new(aided);
    let mut state = NominalState::at_rest(LAT, 0.0, ALT);
    state.attitude = quaternion_from_euler(0.0, 0.0, 0.0);
    let mut diag = [0.0; 15];
    for (k, d) in diag.iter_mut().enumerate() {
        *d = match k {
            0..=2 => 1e-6,
            3..=5 => 0.01,
            6..=8 => 4.0,
            _ => 1e-8,
        };
    }
    nav.take_over(0, state, ImuBias::default(), &diag);
    let g = nav.ekf().expect("navigating").strapdown().gravity();
    let noise = Normal::new(0.0, 1.5).expect("σ");
    let vnoise = Normal::new(0.0, 0.1).expect("σ");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut outcomes = Vec::new();
    let mut largest_step: f64 = 0.0;
    let mut last = PastState::now(nav.ekf().expect("navigating"), Vector3::zeros());
    for i in 1..=(seconds * 1000.0) as u64 {
        let t_us = i * 1_000;
        nav.on_imu(t_us, [0.0; 3], [0.0, 0.0, -g], None);
        if i % 200 == 0 {
            let t_s = t_us as f64 * 1e-6;
            let [n, e] = fix_at(t_s);
            if n.is_nan() {
                // No fix (an outage).
                continue;
            }
            let n = n + noise.sample(&mut rng);
            let e = e + noise.sample(&mut rng);
            let m = GnssMeasurement {
                t_us: t_us - 80_000,
                receiver_time_us: t_us,
                fix_3d: true,
                position: [
                    lat_north(n),
                    e / ((prime_vertical_radius(LAT) + ALT) * LAT.cos()),
                    ALT,
                ],
                velocity_ned: Some([
                    vnoise.sample(&mut rng),
                    vnoise.sample(&mut rng),
                    vnoise.sample(&mut rng),
                ]),
                sigma_h_m: 1.5,
                sigma_v_m: 3.0,
                sigma_vel_mps: 0.1,
            };
            outcomes.push((t_s, nav.on_gnss(&m)));
        }
        let now = PastState::now(nav.ekf().expect("navigating"), Vector3::zeros());
        let step = last.ned_to(now.lat, now.lon, now.alt);
        // From 20 s on: the first fixes pull the start in by their noise, by design.
        if i > 20_000 {
            largest_step = largest_step.max(step.x.hypot(step.y));
        }
        last = now;
    }
    (nav, outcomes, largest_step)
}

#[test]
fn a_true_receiver_is_used_throughout_and_never_rejected() {
    let (nav, outcomes, _) = hover(120.0, |_| [0.0, 0.0]);
    let applied = outcomes
        .iter()
        .filter(|(_, o)| matches!(o, GnssOutcome::Applied { .. }))
        .count();
    assert!(
        applied >= outcomes.len() - 3,
        "{applied} of {}",
        outcomes.len()
    );
    assert_eq!(nav.gnss_monitor().rejections(), 0);
}

#[test]
fn a_50_m_jump_is_rejected_within_a_second_without_moving_the_solution() {
    let (nav, outcomes, largest_step) =
        hover(60.0, |t| if t >= 30.0 { [50.0, 0.0] } else { [0.0, 0.0] });
    let rejected_at = outcomes
        .iter()
        .find(|(_, o)| *o == GnssOutcome::Rejected)
        .map(|(t, _)| *t)
        .expect("rejected");
    assert!(
        (30.0..=31.0).contains(&rejected_at),
        "rejected at {rejected_at} s"
    );
    assert_eq!(nav.gnss_monitor().rejected(), Some(RejectReason::Jump));
    assert!(largest_step < 1.0, "the solution stepped {largest_step} m");
}

#[test]
fn a_half_metre_per_second_drift_is_detected_within_30_s() {
    let (nav, outcomes, _) = hover(60.0, |t| [0.5 * (t - 30.0).max(0.0), 0.0]);
    let rejected_at = outcomes
        .iter()
        .find(|(_, o)| *o == GnssOutcome::Rejected)
        .map(|(t, _)| *t)
        .expect("drift detected");
    assert!(
        (30.0..=60.0).contains(&rejected_at),
        "detected at {rejected_at} s"
    );
    assert_eq!(nav.gnss_monitor().rejected(), Some(RejectReason::Drift));
}

#[test]
fn after_an_outage_the_first_fix_resets_the_position_and_nothing_is_rejected() {
    // No fixes from 20 s to 80 s; then the truth again.
    let (nav, outcomes, _) = hover(100.0, |t| {
        if (20.0..80.0).contains(&t) {
            [f64::NAN; 2]
        } else {
            [0.0, 0.0]
        }
    });
    let back = outcomes.iter().find(|(t, _)| *t >= 80.0).map(|(_, o)| *o);
    assert_eq!(back, Some(GnssOutcome::Readmitted));
    assert_eq!(nav.gnss_monitor().rejections(), 0);
    let ekf = nav.ekf().expect("navigating");
    let here = PastState::now(ekf, Vector3::zeros()).ned_to(LAT, 0.0, ALT);
    assert!(here.x.hypot(here.y) < 3.0, "{here}");
}

#[test]
fn a_receiver_that_jumps_back_is_readmitted_and_one_that_stays_away_is_not() {
    let (nav, outcomes, _) = hover(70.0, |t| {
        if (30.0..45.0).contains(&t) {
            [50.0, 0.0]
        } else {
            [0.0, 0.0]
        }
    });
    let back = outcomes
        .iter()
        .find(|(_, o)| *o == GnssOutcome::Readmitted)
        .map(|(t, _)| *t)
        .expect("readmitted");
    // Consistent again from 45 s, back after readmit_after_s (3 s).
    assert!((48.0..=49.0).contains(&back), "readmitted at {back} s");
    assert_eq!(nav.gnss_monitor().rejected(), None);
    // A jump that stays: still out two minutes later, however far the coast's covariance grew.
    let (nav, _, _) = hover(150.0, |t| if t >= 30.0 { [50.0, 0.0] } else { [0.0, 0.0] });
    assert_eq!(nav.gnss_monitor().rejected(), Some(RejectReason::Jump));
}
