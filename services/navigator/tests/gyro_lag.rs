//! A unit whose gyro channel lags its accelerometer's: the roll it reports trails the specific
//! force it measures, so the force is turned with a stale attitude and gravity leaks into the
//! horizontal velocity. Pairing each rate with the force of the lag before (`gyro_lag_s`) puts
//! the two back on one instant.

use rins_navigator::NavigatorConfig;
use rins_navigator::inertial_core::AidedNavigator;

const G: f64 = 9.80;
const RATE_HZ: f64 = 400.0;
/// How much the simulated gyro channel lags, s (4 samples).
const LAG_S: f64 = 0.01;
/// Roll oscillation: amplitude, rad, and frequency, Hz.
const ROLL_AMPLITUDE: f64 = 0.5;
const ROLL_HZ: f64 = 2.0;
const STILL_S: f64 = 1.5;
const ROCK_S: f64 = 2.0;

fn roll(t: f64) -> f64 {
    let tau = (t - STILL_S).max(0.0);
    ROLL_AMPLITUDE * (std::f64::consts::TAU * ROLL_HZ * tau).sin()
}

/// The largest horizontal speed while rocking in place, the gyro reading `LAG_S` late, with the
/// navigator's `gyro_lag_s` set to `compensation`.
fn speed_after_rocking(compensation: f64) -> f64 {
    speed_after_rocking_lag(LAG_S, compensation)
}

fn speed_after_rocking_lag(lag: f64, compensation: f64) -> f64 {
    let mut config = NavigatorConfig {
        initial_latitude_deg: Some(45.0),
        initial_longitude_deg: Some(7.0),
        gyro_lag_s: compensation,
        ..NavigatorConfig::default()
    }
    .aided_config();
    config.zupt.enabled = false;
    let mut nav = AidedNavigator::new(config);
    let n = ((STILL_S + ROCK_S) * RATE_HZ) as usize;
    let mut fastest: f64 = 0.0;
    for k in 0..n {
        let t = k as f64 / RATE_HZ;
        // The sample stands for the interval that ends at it: the rate is the interval's mean
        // (its roll increment over the step), the force the mid-interval one (what the
        // mechanisation turns with the mid-step attitude). Level, rolled by φ about x (FRD):
        // gravity's reaction in the body is (0, −g sinφ, −g cosφ).
        let dt = 1.0 / RATE_HZ;
        let phi = roll(t - dt / 2.0);
        let force = [0.0, -G * phi.sin(), -G * phi.cos()];
        let rate = [(roll(t - lag) - roll(t - lag - dt)) / dt, 0.0, 0.0];
        nav.on_imu((t * 1e6).round() as u64, rate, force, None);
        if let Some(ekf) = nav.ekf() {
            let v = ekf.state().velocity_ned;
            fastest = fastest.max(v.x.hypot(v.y));
        }
    }
    assert!(nav.ekf().is_some(), "aligned in the still start");
    fastest
}

#[test]
fn pairing_the_rate_with_the_force_of_the_lag_before_stops_gravity_leaking() {
    let uncompensated = speed_after_rocking(0.0);
    let compensated = speed_after_rocking(LAG_S);
    // Turned with an attitude 10 ms stale, the force's horizontal part is g·(φ(t) − φ(t − lag))
    // ≈ g·φ₀·ω·lag·cos(ωt) while rocking, a velocity swinging by g·φ₀·lag = 9.8 · 0.5 · 0.01 ≈
    // 0.05 m/s. Paired again, rate and force describe one instant and nothing leaks (the samples
    // are exact increments, so only rounding is left).
    let expected = G * ROLL_AMPLITUDE * LAG_S;
    assert!(
        (uncompensated / expected - 1.0).abs() < 0.2,
        "uncompensated {uncompensated} m/s against {expected}"
    );
    assert!(
        compensated < 0.01 * uncompensated,
        "compensated {compensated} m/s against {uncompensated} m/s"
    );
}
