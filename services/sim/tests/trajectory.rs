//! Truth trajectory: mutual consistency of attitude/rate and velocity/acceleration/position, and the
//! shape of the UAV profile.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rins_earth::STANDARD_GRAVITY;
use rins_sim::trajectory::geodesy::geodetic_rates;
use rins_sim::trajectory::uav_profile::{
    CRUISE_ALTITUDE_AGL_M, CRUISE_SPEED_MPS, MAX_BANK_DEG, MIN_BANK_DEG,
};
use rins_sim::{Scenario, SimConfig, Trajectory, TruthState};

fn uav() -> (Trajectory, SimConfig) {
    let config = SimConfig {
        scenario: Scenario::Uav,
        initial_heading_deg: 30.0,
        ..SimConfig::default()
    };
    (
        Trajectory::new(Scenario::Uav, config.trajectory_start()),
        config,
    )
}

fn q_dot(q: &Quaternion<f64>, w: &Vector3<f64>) -> Quaternion<f64> {
    q * Quaternion::new(0.0, w.x, w.y, w.z) * 0.5
}

fn nav_accel(s: &TruthState) -> Vector3<f64> {
    s.attitude.transform_vector(&s.specific_force_b) + Vector3::new(0.0, 0.0, STANDARD_GRAVITY)
}

fn geo_rates(s: &TruthState, lat: f64) -> [f64; 2] {
    geodetic_rates(lat, s.altitude_m, s.velocity_n.x, s.velocity_n.y)
}

/// Integrates the sampled body rate (RK4 on q̇ = ½ q ⊗ ω), the specific force rotated by the
/// integrated attitude plus gravity (Simpson), and the curvilinear position equations (RK4) at 1 kHz
/// over the whole profile. RK4/Simpson global error is O(h⁴): with h = 1 ms and derivatives of order
/// one, about 1e-12 per unit time, so over ~620 s attitude and velocity must match to ≲1e-9.
/// Position is limited by round-off of latitude (~1e-16 rad ≈ 1 nm per step, random-walking over
/// 6e5 steps to ~1 µm), hence 10 µm. A wrong sign or a missing term anywhere gives errors of
/// order one.
#[test]
fn integrated_rates_and_accelerations_reproduce_the_sampled_truth() {
    let (traj, _) = uav();
    let h = 1e-3;
    let steps = ((traj.end_s() + 5.0) / h) as usize;
    let first = traj.sample(0.0);
    let mut q = *first.attitude.quaternion();
    let mut v = first.velocity_n;
    let (mut lat, mut lon) = (first.latitude_rad, first.longitude_rad);
    let (mut max_att, mut max_vel, mut max_pos) = (0.0_f64, 0.0_f64, 0.0_f64);
    let mut prev = first;
    for k in 0..steps {
        let t = k as f64 * h;
        let mid = traj.sample(t + 0.5 * h);
        let end = traj.sample(t + h);

        // Attitude: classic RK4 with rates at t, t+h/2, t+h.
        let k1 = q_dot(&q, &prev.angular_rate_b);
        let k2 = q_dot(&(q + k1 * (0.5 * h)), &mid.angular_rate_b);
        let k3 = q_dot(&(q + k2 * (0.5 * h)), &mid.angular_rate_b);
        let k4 = q_dot(&(q + k3 * h), &end.angular_rate_b);
        q += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (h / 6.0);
        q = q.normalize();

        // Velocity: Simpson on the navigation-frame acceleration rebuilt from f_b and the truth attitude.
        v += (nav_accel(&prev) + nav_accel(&mid) * 4.0 + nav_accel(&end)) * (h / 6.0);

        // Position: RK4 of φ̇ = v_N/(R_M+h), λ̇ = v_E/((R_N+h) cos φ) with the truth velocity.
        let r1 = geo_rates(&prev, lat);
        let r2 = geo_rates(&mid, lat + 0.5 * h * r1[0]);
        let r3 = geo_rates(&mid, lat + 0.5 * h * r2[0]);
        let r4 = geo_rates(&end, lat + h * r3[0]);
        lat += h / 6.0 * (r1[0] + 2.0 * r2[0] + 2.0 * r3[0] + r4[0]);
        lon += h / 6.0 * (r1[1] + 2.0 * r2[1] + 2.0 * r3[1] + r4[1]);

        if k % 10 == 9 {
            let att_err = UnitQuaternion::from_quaternion(q).angle_to(&end.attitude);
            max_att = max_att.max(att_err);
            max_vel = max_vel.max((v - end.velocity_n).norm());
            let north_m = (lat - end.latitude_rad) * 6.4e6;
            let east_m = (lon - end.longitude_rad) * 6.4e6 * lat.cos();
            max_pos = max_pos.max(north_m.hypot(east_m));
        }
        prev = end;
    }
    eprintln!(
        "max errors: attitude {max_att:e} rad, velocity {max_vel:e} m/s, position {max_pos:e} m"
    );
    assert!(max_att < 1e-9, "attitude error {max_att:e} rad");
    assert!(max_vel < 1e-8, "velocity error {max_vel:e} m/s");
    assert!(max_pos < 1e-5, "position error {max_pos:e} m");
    // The profile really moved: the check above is not vacuous.
    let last = traj.sample(traj.end_s());
    let moved_m = (last.latitude_rad - first.latitude_rad).abs() * 6.4e6;
    assert!(moved_m > 50.0 || (last.longitude_rad - first.longitude_rad).abs() * 4e6 > 50.0);
}

/// Rates and accelerations must not jump: over 1 ms they change by at most
/// (max angular acceleration)·h and (max jerk)·h. The largest roll acceleration is about
/// (V/g)·ψ̇_max·2π/T² ≈ 0.4 rad/s² and the largest jerk, at turn entry, V·2ψ̇_max/T ≈ 3.8 m/s³
/// (V = 15 m/s, ψ̇_max = 0.377 rad/s at 30° bank, T = 3 s); a step would show up as hundreds.
#[test]
fn rates_and_accelerations_are_continuous() {
    let (traj, _) = uav();
    let h = 1e-3;
    let mut prev = traj.sample(0.0);
    let (mut max_ang_acc, mut max_jerk) = (0.0_f64, 0.0_f64);
    for k in 1..((traj.end_s() + 1.0) / h) as usize {
        let s = traj.sample(k as f64 * h);
        max_ang_acc = max_ang_acc.max((s.angular_rate_b - prev.angular_rate_b).norm() / h);
        max_jerk = max_jerk.max((s.acceleration_n - prev.acceleration_n).norm() / h);
        prev = s;
    }
    assert!(
        max_ang_acc < 1.0,
        "angular acceleration {max_ang_acc} rad/s²"
    );
    assert!(max_jerk < 4.0, "jerk {max_jerk} m/s³");
    assert!(max_ang_acc > 0.05, "the profile does turn");
}

/// Coordinated flight: the lateral specific force is zero at every instant, and the vertical body
/// axis carries the load factor 1/cos φ in level turns.
#[test]
fn turns_are_coordinated() {
    let (traj, _) = uav();
    let mut max_lateral = 0.0_f64;
    let mut checked_turn = false;
    for k in 0..(traj.end_s() * 100.0) as usize {
        let s = traj.sample(k as f64 * 0.01);
        max_lateral = max_lateral.max(s.specific_force_b.y.abs());
        let [roll, pitch, _] = s.euler_rad;
        if roll.abs() > 15f64.to_radians() && pitch == 0.0 && s.velocity_n.z == 0.0 {
            let expected = -STANDARD_GRAVITY / roll.cos();
            assert!(
                (s.specific_force_b.z - expected).abs() < 1e-9,
                "load factor at t={}",
                s.time_s
            );
            checked_turn = true;
        }
    }
    assert!(max_lateral < 1e-9, "lateral specific force {max_lateral}");
    assert!(checked_turn);
}

#[test]
fn uav_profile_climbs_to_cruise_banks_within_limits_and_lands() {
    let (traj, config) = uav();
    let ground = config.origin_altitude_m;
    assert!(traj.end_s() >= 600.0, "profile lasts {} s", traj.end_s());

    let (mut max_alt, mut max_roll, mut min_roll, mut max_pitch) =
        (f64::MIN, 0.0_f64, 0.0_f64, 0.0_f64);
    let mut max_speed = 0.0_f64;
    for k in 0..(traj.end_s() * 10.0) as usize {
        let t = k as f64 * 0.1;
        let s = traj.sample(t);
        max_alt = max_alt.max(s.altitude_m - ground);
        max_roll = max_roll.max(s.euler_rad[0]);
        min_roll = min_roll.min(s.euler_rad[0]);
        max_pitch = max_pitch.max(s.euler_rad[1].abs());
        max_speed = max_speed.max(s.velocity_n.xy().norm());
        assert!(s.altitude_m >= ground - 1e-9, "below ground at t={t}");
        if t < config.static_s {
            assert_eq!(s.velocity_n, Vector3::zeros());
            assert_eq!(s.angular_rate_b, Vector3::zeros());
            assert!(
                (s.specific_force_b - Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)).norm() < 1e-12
            );
        }
    }
    assert!(
        (max_alt - CRUISE_ALTITUDE_AGL_M).abs() < 1e-6,
        "max altitude AGL {max_alt}"
    );
    assert!((max_speed - CRUISE_SPEED_MPS).abs() < 1e-9);
    // Right turns at 25° and 30°, left turns at 20° (sampled at 10 Hz, so peaks are reached on holds).
    assert!(
        (max_roll.to_degrees() - MAX_BANK_DEG).abs() < 1e-6,
        "max roll {}",
        max_roll.to_degrees()
    );
    assert!(
        (min_roll.to_degrees() + MIN_BANK_DEG).abs() < 1e-6,
        "min roll {}",
        min_roll.to_degrees()
    );
    assert!(max_pitch.to_degrees() < 15.0);

    for t in [traj.end_s(), traj.end_s() + 100.0, traj.end_s() + 1e5] {
        let s = traj.sample(t);
        assert!(
            (s.altitude_m - ground).abs() < 1e-6,
            "landed altitude {}",
            s.altitude_m
        );
        assert!(s.velocity_n.norm() < 1e-12);
        assert!(s.angular_rate_b.norm() < 1e-12);
        assert!(
            s.euler_rad[0].abs() < 1e-12 && s.euler_rad[1].abs() < 1e-12,
            "level when parked"
        );
        assert!((s.specific_force_b - Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)).norm() < 1e-9);
    }
    let parked = traj.sample(traj.end_s());
    let later = traj.sample(traj.end_s() + 1e5);
    assert_eq!(parked.latitude_rad, later.latitude_rad);
    assert_eq!(parked.longitude_rad, later.longitude_rad);
    assert!(traj.lift_off_s() > config.static_s && traj.touchdown_s() < traj.end_s());
}

#[test]
fn static_scenario_is_level_at_origin_with_configured_heading() {
    let config = SimConfig {
        initial_heading_deg: 123.0,
        ..SimConfig::default()
    };
    let traj = Trajectory::new(Scenario::Static, config.trajectory_start());
    for t in [0.0, 1.0, 1e4] {
        let s = traj.sample(t);
        assert!((s.euler_rad[2] - 123f64.to_radians()).abs() < 1e-15);
        assert_eq!((s.euler_rad[0], s.euler_rad[1]), (0.0, 0.0));
        let (r, p, y) = s.attitude.euler_angles();
        assert!(r.abs() < 1e-12 && p.abs() < 1e-12 && (y - 123f64.to_radians()).abs() < 1e-12);
        assert_eq!(
            s.specific_force_b,
            Vector3::new(0.0, 0.0, -STANDARD_GRAVITY)
        );
        assert_eq!(s.latitude_rad, config.origin_latitude_deg.to_radians());
        assert_eq!(s.longitude_rad, config.origin_longitude_deg.to_radians());
        assert_eq!(s.altitude_m, config.origin_altitude_m);
    }
}

/// A long parked prefix only shifts the profile in time (and costs no table memory).
#[test]
fn static_prefix_shifts_the_profile() {
    let base = uav().0;
    let config = SimConfig {
        scenario: Scenario::Uav,
        initial_heading_deg: 30.0,
        static_s: 3600.0,
        ..SimConfig::default()
    };
    let late = Trajectory::new(Scenario::Uav, config.trajectory_start());
    let shift = 3600.0 - SimConfig::default().static_s;
    assert!((late.end_s() - base.end_s() - shift).abs() < 1e-9);
    for t in [0.0, 100.0, 150.0, 400.0, base.end_s() + 10.0] {
        let (a, b) = (base.sample(t), late.sample(t + shift));
        assert!((a.velocity_n - b.velocity_n).norm() < 1e-9, "t={t}");
        assert!(a.attitude.angle_to(&b.attitude) < 1e-9);
        assert!((a.altitude_m - b.altitude_m).abs() < 1e-6);
        assert!((a.latitude_rad - b.latitude_rad).abs() < 1e-12);
        assert!((a.longitude_rad - b.longitude_rad).abs() < 1e-12);
    }
    let parked = late.sample(3599.0);
    assert_eq!(parked.latitude_rad, config.origin_latitude_deg.to_radians());
    assert_eq!(parked.velocity_n, Vector3::zeros());
}

/// An hour-long flight repeats the circuits: it keeps flying (banked, at cruise speed and
/// altitude) for most of the hour, lands by the end, and its first circuits are the short
/// profile's.
#[test]
fn a_long_flight_repeats_the_circuits_until_it_must_land() {
    let (short, _) = uav();
    let config = SimConfig {
        scenario: Scenario::Uav,
        initial_heading_deg: 30.0,
        uav_flight_s: Some(3600.0),
        ..SimConfig::default()
    };
    let long = Trajectory::new(Scenario::Uav, config.trajectory_start());
    assert!(long.end_s() <= 3600.0, "ends at {} s", long.end_s());
    // One more pair of circuits would not fit: the gap left is shorter than a pair (≈ 424 s).
    let pair_s = (long.end_s() - short.end_s()) / ((long.end_s() - short.end_s()) / 424.0).round();
    assert!(
        (400.0..450.0).contains(&pair_s),
        "pair of circuits {pair_s} s"
    );
    assert!(3600.0 - long.end_s() < pair_s, "ends at {} s", long.end_s());
    // Identical up to the end of the first pair of circuits (the reversal comes later).
    for t in [0.0, 50.0, 200.0, 400.0] {
        let (a, b) = (short.sample(t), long.sample(t));
        assert!(a.attitude.angle_to(&b.attitude) < 1e-12, "t={t}");
        assert!((a.velocity_n - b.velocity_n).norm() < 1e-9, "t={t}");
    }
    // Airborne at cruise speed between take-off and the descent, and banked a good part of it.
    let (mut airborne, mut banked, mut samples) = (0, 0, 0);
    for k in 0..3500 {
        let s = long.sample(k as f64);
        samples += 1;
        airborne += usize::from(s.altitude_m - config.origin_altitude_m > 50.0);
        banked += usize::from(s.euler_rad[0].abs() > 10f64.to_radians());
    }
    // Parked 3 s, climb 44 s, descent 54 s, landing roll and a margin before the hour ends.
    assert!(
        airborne > samples * 85 / 100,
        "airborne {airborne} of {samples} s"
    );
    assert!(banked > samples / 10, "banked {banked} of {samples} s");
    let parked = long.sample(long.end_s() + 1.0);
    assert!((parked.altitude_m - config.origin_altitude_m).abs() < 1e-6);
    assert!(parked.velocity_n.norm() < 1e-12);
    // The configured length is validated: a negative flight is named.
    let bad = SimConfig {
        uav_flight_s: Some(-1.0),
        ..SimConfig::default()
    };
    let e = bad.validate().expect_err("negative flight").to_string();
    assert!(e.contains("sim.uav_flight_s"), "{e}");
}
