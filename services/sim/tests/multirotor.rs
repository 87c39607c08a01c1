//! The multirotor scenario: its specific force is the rotor-drag model's, its attitude and body
//! rate agree, its flight has the intended shape, its rotor vibration aliases as a real IMU's, and
//! it is chosen from the configuration.

mod common;

use std::f64::consts::TAU;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rins_earth::STANDARD_GRAVITY;
use rins_protocol::ImuFrame;
use rins_sim::sensor_model::SensorModel;
use rins_sim::trajectory::multirotor_config::MultirotorConfig;
use rins_sim::{Scenario, SimConfig, Trajectory};
use rins_test_support::pyramid::optimal_pyramid_axes;

fn multirotor(flight_s: Option<f64>) -> (Trajectory, SimConfig) {
    let config = SimConfig {
        scenario: Scenario::Multirotor,
        initial_heading_deg: 30.0,
        uav_flight_s: flight_s,
        ..SimConfig::default()
    };
    (
        Trajectory::new(Scenario::Multirotor, config.trajectory_start()),
        config,
    )
}

/// At instants spread over the whole flight (turns, crabbing, gust, climbs), the body x and y
/// specific force is −μ times the body airspeed. Both come from the same closed-form attitude, so
/// they agree to round-off (g·10⁻¹⁵ per operation, a few dozen operations).
#[test]
fn body_xy_specific_force_is_the_rotor_drag_of_the_airspeed() {
    let (traj, config) = multirotor(Some(600.0));
    let mu = [
        config.multirotor.drag_per_s,
        config.multirotor.lateral_drag_per_s,
    ];
    let (mut worst, mut moving, mut gusty, mut crabbed) = (0.0_f64, 0, 0, 0);
    let mut t = 0.0;
    while t < traj.end_s() + 5.0 {
        let s = traj.sample(t);
        let wind = traj.wind_n(t);
        let air_b = s.attitude.inverse_transform_vector(&(s.velocity_n - wind));
        for axis in 0..2 {
            worst = worst.max((s.specific_force_b[axis] + mu[axis] * air_b[axis]).abs());
        }
        assert!(
            s.specific_force_b.z < -0.5 * STANDARD_GRAVITY,
            "thrust at t={t}"
        );
        moving += usize::from(s.velocity_n.norm() > 3.0);
        gusty += usize::from(wind.norm() > 1.0);
        crabbed += usize::from(air_b.y.abs() > 2.0);
        t += 0.0173;
    }
    assert!(
        worst < 1e-12,
        "largest departure from the drag model {worst} m/s²"
    );
    // The samples did exercise what the test is about.
    assert!(moving > 10_000 && gusty > 1000 && crabbed > 1000);
}

fn q_dot(q: &Quaternion<f64>, w: &Vector3<f64>) -> Quaternion<f64> {
    q * Quaternion::new(0.0, w.x, w.y, w.z) * 0.5
}

/// Integrating the body rate (RK4) and the specific force rotated by the truth attitude plus
/// gravity (Simpson) at 1 kHz reproduces the attitude and velocity. The roll and pitch rates are
/// central differences with an error under 10⁻⁵ rad/s, whose sign follows the manoeuvres, so the
/// attitude may drift by at most ~10⁻⁵ rad/s × 10 s of turning per pattern; 2·10⁻⁴ rad bounds it.
#[test]
fn integrated_rates_and_forces_reproduce_the_truth() {
    let (traj, _) = multirotor(None);
    let h = 1e-3;
    let steps = ((traj.end_s() + 2.0) / h) as usize;
    let mut prev = traj.sample(0.0);
    let mut q = *prev.attitude.quaternion();
    let mut v = prev.velocity_n;
    let g = Vector3::new(0.0, 0.0, STANDARD_GRAVITY);
    let (mut max_att, mut max_vel) = (0.0_f64, 0.0_f64);
    for k in 0..steps {
        let t = k as f64 * h;
        let mid = traj.sample(t + 0.5 * h);
        let end = traj.sample(t + h);
        let k1 = q_dot(&q, &prev.angular_rate_b);
        let k2 = q_dot(&(q + k1 * (0.5 * h)), &mid.angular_rate_b);
        let k3 = q_dot(&(q + k2 * (0.5 * h)), &mid.angular_rate_b);
        let k4 = q_dot(&(q + k3 * h), &end.angular_rate_b);
        q = (q + (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0)).normalize();
        let a = |s: &rins_sim::TruthState| s.attitude.transform_vector(&s.specific_force_b) + g;
        v += (a(&prev) + a(&mid) * 4.0 + a(&end)) * (h / 6.0);
        let err = UnitQuaternion::from_quaternion(q).angle_to(&end.attitude);
        max_att = max_att.max(err);
        max_vel = max_vel.max((v - end.velocity_n).norm());
        prev = end;
    }
    assert!(max_att < 2e-4, "attitude drift {max_att} rad");
    assert!(max_vel < 1e-6, "velocity drift {max_vel} m/s");
}

#[test]
fn the_flight_is_quadrotor_like_and_lands_stopped() {
    let (traj, config) = multirotor(Some(600.0));
    let (mut max_tilt, mut max_speed, mut max_wind) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut max_agl, mut min_hz, mut max_hz) = (0.0_f64, f64::INFINITY, 0.0_f64);
    let mut t = traj.lift_off_s();
    while t < traj.touchdown_s() {
        let s = traj.sample(t);
        let [roll, pitch, _] = s.euler_rad;
        max_tilt = max_tilt.max((roll.cos() * pitch.cos()).acos().to_degrees());
        max_speed = max_speed.max(s.velocity_n.norm());
        max_wind = max_wind.max(traj.wind_n(t).norm());
        max_agl = max_agl.max(s.altitude_m - config.origin_altitude_m);
        let hz = traj.blade_pass_hz(t);
        (min_hz, max_hz) = (min_hz.min(hz), max_hz.max(hz));
        t += 0.05;
    }
    assert!((25.0..=35.0).contains(&max_tilt), "max tilt {max_tilt}°");
    assert!((9.5..=11.0).contains(&max_speed), "max speed {max_speed}");
    assert!((max_wind - config.multirotor.gust_mps).abs() < 1e-9);
    assert!((max_agl - 40.0).abs() < 1e-6, "highest {max_agl} m");
    assert!(min_hz >= 160.0 && max_hz <= 240.0 && max_hz - min_hz > 20.0);
    // A 10-minute flight fills its time and lands where it took off, stopped and level.
    assert!(traj.end_s() <= 600.0 && traj.end_s() > 500.0);
    let landed = traj.sample(traj.end_s() + 1.0);
    assert!(landed.stance);
    assert!((landed.altitude_m - config.origin_altitude_m).abs() < 1e-6);
    assert_eq!(landed.velocity_n, Vector3::zeros());
    assert!(landed.euler_rad[0].abs() < 1e-12 && landed.euler_rad[1].abs() < 1e-12);
    assert_eq!(landed.rotor.accel_amplitude_mps2, 0.0);
    // Parked for the alignment with the rotors stopped.
    let parked = traj.sample(0.5 * config.static_s);
    assert!(parked.stance && parked.rotor.accel_amplitude_mps2 == 0.0);
}

/// Amplitude of the component of `x` at `hz` when sampled at `rate_hz`.
fn amplitude_at(x: &[f64], rate_hz: f64, hz: f64) -> f64 {
    let (mut c, mut s) = (0.0, 0.0);
    for (k, v) in x.iter().enumerate() {
        let a = TAU * hz * k as f64 / rate_hz;
        c += v * a.cos();
        s += v * a.sin();
    }
    2.0 * (c * c + s * s).sqrt() / x.len() as f64
}

/// In the hover after the climb the thrust is g, so the blade passes at 200 Hz. Sampled at
/// 250 Hz without anti-alias filter an accelerometer sees it at 50 Hz, with the amplitude of the
/// vibration's projection on its axis; noise and bias are off, so what is left is the 12-bit
/// quantisation (lsb/√12 spread over the band).
#[test]
fn rotor_vibration_aliases_below_half_a_low_imu_rate() {
    let (traj, config) = multirotor(None);
    let rate_hz = 250.0;
    let axes = optimal_pyramid_axes();
    let mut model = SensorModel::new(
        &common::noiseless_sensors(),
        &config.environment(),
        &axes,
        &axes,
        rate_hz,
        3,
    )
    .unwrap();
    // Hover: 2 s spin-up and 12 s climb after the parking, then 5 s still.
    let hover_s = config.static_s + 14.5;
    assert!((traj.blade_pass_hz(hover_s) - 200.0).abs() < 1e-6);
    let n = 1000; // 4 s
    let mut frame = ImuFrame::default();
    let lsb = config.accel_lsb_mps2();
    let axis = Vector3::from(axes[0]);
    let mut x = Vec::with_capacity(n);
    let mut expected = 0.0_f64;
    for k in 0..n {
        let s = traj.sample(hover_s + k as f64 / rate_hz);
        model.imu(&s, &mut frame);
        x.push(f64::from(frame.accel_counts[0]) * lsb - axis.dot(&s.specific_force_b));
        let (_, f) = rins_sim::sensor_model::vibration::body_vibration(&s.rotor);
        expected = expected.max(axis.dot(&f).abs());
    }
    let alias = amplitude_at(&x, rate_hz, 50.0);
    assert!(expected > 1.0, "the channel sees the vibration");
    // The peak over 1000 samples of a 50 Hz sinusoid at 250 Hz is its amplitude to 5 %.
    assert!(
        (alias - expected).abs() < 0.05 * expected + lsb,
        "{alias} vs {expected}"
    );
    for other in [5.0, 20.0, 35.0, 70.0, 100.0, 120.0] {
        assert!(
            amplitude_at(&x, rate_hz, other) < 0.1 * lsb + 0.02,
            "{other} Hz"
        );
    }
}

#[test]
fn the_scenario_and_its_airframe_parse_from_the_configuration() {
    let c: SimConfig = toml::from_str(
        "scenario = \"multirotor\"\n[multirotor]\ndrag_per_s = 0.5\nvibration_accel_mps2 = 1.0\n",
    )
    .unwrap();
    assert_eq!(c.scenario, Scenario::Multirotor);
    assert_eq!(
        c.multirotor,
        MultirotorConfig {
            drag_per_s: 0.5,
            vibration_accel_mps2: 1.0,
            ..MultirotorConfig::default()
        }
    );
    c.validate().unwrap();
    // The defaults are the drag the uav profile's navigator was fitted to.
    let d = MultirotorConfig::default();
    assert_eq!((d.drag_per_s, d.lateral_drag_per_s), (0.4, 0.6));
    let bad = SimConfig {
        multirotor: MultirotorConfig {
            lateral_drag_per_s: -0.1,
            ..d
        },
        ..c
    };
    let e = bad.validate().unwrap_err().to_string();
    assert!(
        e.contains("sim.multirotor.lateral_drag_per_s") && e.contains("-0.1"),
        "{e}"
    );
    assert!(toml::from_str::<SimConfig>("[multirotor]\nmu = 1.0\n").is_err());
}
