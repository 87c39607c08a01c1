//! The walk scenario: a foot-mounted sensor walked once round the 50 m × 12.9 m rectangle. Closed
//! path of the right size, truth that integrates to itself, exact rest during stance, plausible
//! swing dynamics, the foot-pressure load, and the configuration switch.

mod common;

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use rins_earth::STANDARD_GRAVITY;
use rins_earth::{meridian_radius, prime_vertical_radius};
use rins_protocol::{FrameType, Payload};
use rins_sim::trajectory::geodesy::geodetic_rates;
use rins_sim::trajectory::walk::{
    self, COURSE_LENGTH_M, COURSE_WIDTH_M, FINAL_STAND_S, LIFT_M, LOAD_RAMP_S, PATH_LENGTH_M,
    STANCE_LOAD, STANCE_S, STRIDE_PERIOD_S, SWING_S, WalkPath,
};
use rins_sim::{Scenario, SimConfig, Simulator, TickOutput, Trajectory, TruthState};
use rins_test_support::counting_alloc::{CountingAllocator, allocations_during};
use rins_test_support::pyramid::optimal_pyramid_axes;

#[global_allocator]
static ALLOCATOR: CountingAllocator = CountingAllocator;

/// Truth is sampled on the simulator's 1 kHz grid.
const H: f64 = 1e-3;

fn walk_config(heading_deg: f64, static_s: f64) -> SimConfig {
    SimConfig {
        scenario: Scenario::Walk,
        initial_heading_deg: heading_deg,
        static_s,
        ..SimConfig::default()
    }
}

fn walk(heading_deg: f64) -> (Trajectory, WalkPath, SimConfig) {
    let config = walk_config(heading_deg, 3.0);
    let start = config.trajectory_start();
    (
        Trajectory::new(Scenario::Walk, start),
        WalkPath::new(start),
        config,
    )
}

/// Samples on the 1 kHz grid from 0 to one second past the end of the walk.
fn grid(traj: &Trajectory) -> impl Iterator<Item = f64> {
    let n = ((traj.end_s() + 1.0) / H).round() as usize;
    (0..=n).map(|k| k as f64 * H)
}

/// Local north/east/down offset from the origin recovered from latitude, longitude and altitude
/// with the origin's radii of curvature (the inverse of the walk's flat map).
fn local_from_geodetic(s: &TruthState, config: &SimConfig) -> Vector3<f64> {
    let (lat0, lon0, h0) = (
        config.origin_latitude_deg.to_radians(),
        config.origin_longitude_deg.to_radians(),
        config.origin_altitude_m,
    );
    Vector3::new(
        (s.latitude_rad - lat0) * (meridian_radius(lat0) + h0),
        (s.longitude_rad - lon0) * (prime_vertical_radius(lat0) + h0) * lat0.cos(),
        h0 - s.altitude_m,
    )
}

/// The construction: 38 strides of 50/38 m on the long sides and 10 of 1.29 m on the short ones,
/// 96 in all; the path is exactly the perimeter, 125.8 m; the walk lasts 95 gait cycles plus one
/// swing after the 3 s stand, and ends 5 s after the last heel strike.
#[test]
fn schedule_has_the_documented_size() {
    assert_eq!(walk::strides_per_side(COURSE_LENGTH_M), 38);
    assert_eq!(walk::strides_per_side(COURSE_WIDTH_M), 10);
    assert_eq!(walk::stride_count(), 96);
    assert!((PATH_LENGTH_M - 125.8).abs() < 1e-12);
    let (traj, _, _) = walk(0.0);
    assert_eq!(traj.lift_off_s(), 3.0);
    let touchdown = 3.0 + 95.0 * STRIDE_PERIOD_S + SWING_S;
    assert!((traj.touchdown_s() - touchdown).abs() < 1e-9);
    assert!((traj.end_s() - touchdown - FINAL_STAND_S).abs() < 1e-9);
    assert!((traj.end_s() - 108.35).abs() < 1e-9);
}

/// Closed loop, length and extent. Within a swing the foot moves along a straight line and the
/// path changes direction only at corners, where the foot is at rest, so the polyline through the 1 kHz samples has exactly the path's length
/// (rounding ~1e-12 m). Checked for heading 0 (north, then east) and for a rotated course (30°),
/// whose extent is measured along and across the initial heading. Latitude/longitude/altitude must
/// map back to the local position within 1 µm (round-off of a latitude is ~1 nm).
#[test]
fn path_is_the_closed_50_by_12_9_rectangle() {
    for heading_deg in [0.0, 30.0] {
        let (traj, path, config) = walk(heading_deg);
        let (s, c) = heading_deg.to_radians().sin_cos();
        let start = path.position_n(0.0);
        let mut prev = start;
        let mut length = 0.0;
        let (mut lo, mut hi) = (Vector3::repeat(f64::MAX), Vector3::repeat(f64::MIN));
        let mut max_geo_err = 0.0_f64;
        for t in grid(&traj) {
            let p = path.position_n(t);
            length += (p - prev).xy().norm();
            prev = p;
            // Along and across the initial heading (right of it positive), down.
            let course = Vector3::new(c * p.x + s * p.y, -s * p.x + c * p.y, p.z);
            lo = lo.inf(&course);
            hi = hi.sup(&course);
            let geo = local_from_geodetic(&traj.sample(t), &config);
            max_geo_err = max_geo_err.max((geo - p).norm());
        }
        let end = path.position_n(traj.end_s());
        assert!(
            (end - start).norm() < 1e-3,
            "returns to the start: {end} vs {start}"
        );
        assert!(
            (length - PATH_LENGTH_M).abs() < 1e-3,
            "path length {length} m, expected {PATH_LENGTH_M} m"
        );
        assert!(
            lo.x.abs() < 1e-2 && (hi.x - COURSE_LENGTH_M).abs() < 1e-2,
            "{lo} {hi}"
        );
        assert!(
            lo.y.abs() < 1e-2 && (hi.y - COURSE_WIDTH_M).abs() < 1e-2,
            "{lo} {hi}"
        );
        assert!(hi.z.abs() < 1e-12, "never below the floor");
        assert!((lo.z + LIFT_M).abs() < 1e-9, "peak lift {} m", -lo.z);
        assert!(max_geo_err < 1e-6, "geodetic mapping error {max_geo_err} m");
        assert_eq!(
            traj.sample(0.0).latitude_rad,
            config.origin_latitude_deg.to_radians()
        );
    }
}

/// The flat latitude/longitude map against the curvilinear mechanisation a navigator integrates,
/// φ̇ = v_N/(R_M(φ)+h), λ̇ = v_E/((R_N(φ)+h) cos φ) (RK4 at 1 kHz on the truth velocity, whose
/// own error is ~1e-12 m). Across the course (up to ~50 m north) cos φ changes by
/// tan φ·Δφ ≈ 1.09 × 50/6.37e6 ≈ 8.6e-6 relative at 47.4° latitude, which scales east excursions
/// of up to 25 m (course rotated by 30°) by ~2e-4 m; the radii change far less. Bounded by the
/// documented 0.3 mm.
#[test]
fn flat_geodetic_map_matches_the_curvilinear_mechanisation() {
    let (traj, _, _) = walk(30.0);
    let first = traj.sample(0.0);
    let (mut lat, mut lon) = (first.latitude_rad, first.longitude_rad);
    let rates = |s: &TruthState, lat: f64| {
        geodetic_rates(lat, s.altitude_m, s.velocity_n.x, s.velocity_n.y)
    };
    let mut max_err = 0.0_f64;
    let mut prev = first;
    for t in grid(&traj).skip(1) {
        let mid = traj.sample(t - 0.5 * H);
        let end = traj.sample(t);
        let r1 = rates(&prev, lat);
        let r2 = rates(&mid, lat + 0.5 * H * r1[0]);
        let r3 = rates(&mid, lat + 0.5 * H * r2[0]);
        let r4 = rates(&end, lat + H * r3[0]);
        lat += H / 6.0 * (r1[0] + 2.0 * r2[0] + 2.0 * r3[0] + r4[0]);
        lon += H / 6.0 * (r1[1] + 2.0 * r2[1] + 2.0 * r3[1] + r4[1]);
        let north = (lat - end.latitude_rad) * meridian_radius(lat);
        let east = (lon - end.longitude_rad) * prime_vertical_radius(lat) * lat.cos();
        max_err = max_err.max(north.hypot(east));
        prev = end;
    }
    eprintln!("flat map vs curvilinear: {max_err:e} m");
    assert!(max_err < 3e-4, "{max_err} m");
}

fn q_dot(q: &Quaternion<f64>, w: &Vector3<f64>) -> Quaternion<f64> {
    q * Quaternion::new(0.0, w.x, w.y, w.z) * 0.5
}

/// Navigation-frame acceleration rebuilt from the truth specific force and attitude `q`.
fn nav_accel(q: &Quaternion<f64>, s: &TruthState) -> Vector3<f64> {
    UnitQuaternion::from_quaternion(*q).transform_vector(&s.specific_force_b)
        + Vector3::new(0.0, 0.0, STANDARD_GRAVITY)
}

/// Largest errors of a strapdown integration of the truth body rate and specific force.
struct StrapdownErrors {
    attitude_rad: f64,
    velocity_mps: f64,
    position_m: f64,
}

/// Integrates q̇ = ½ q ⊗ ω, v̇ = C(q) f + g, ṗ = v as one system with classic RK4 from the initial
/// truth, the grid offset by `offset_s` from the sample grid, over the whole walk; returns the
/// largest deviation from the truth.
fn strapdown(traj: &Trajectory, path: &WalkPath, offset_s: f64) -> StrapdownErrors {
    let first = traj.sample(offset_s);
    let mut q = *first.attitude.quaternion();
    let mut v = first.velocity_n;
    let mut p = path.position_n(offset_s);
    let mut errors = StrapdownErrors {
        attitude_rad: 0.0,
        velocity_mps: 0.0,
        position_m: 0.0,
    };
    let steps = ((traj.end_s() + 1.0) / H) as usize;
    let mut prev = first;
    for k in 0..steps {
        let t = offset_s + k as f64 * H;
        let mid = traj.sample(t + 0.5 * H);
        let end = traj.sample(t + H);

        let (q1, v1) = (q, v);
        let (dq1, dv1, dp1) = (q_dot(&q1, &prev.angular_rate_b), nav_accel(&q1, &prev), v1);
        let (q2, v2) = (q + dq1 * (0.5 * H), v + dv1 * (0.5 * H));
        let (dq2, dv2, dp2) = (q_dot(&q2, &mid.angular_rate_b), nav_accel(&q2, &mid), v2);
        let (q3, v3) = (q + dq2 * (0.5 * H), v + dv2 * (0.5 * H));
        let (dq3, dv3, dp3) = (q_dot(&q3, &mid.angular_rate_b), nav_accel(&q3, &mid), v3);
        let (q4, v4) = (q + dq3 * H, v + dv3 * H);
        let (dq4, dv4, dp4) = (q_dot(&q4, &end.angular_rate_b), nav_accel(&q4, &end), v4);
        q = (q + (dq1 + dq2 * 2.0 + dq3 * 2.0 + dq4) * (H / 6.0)).normalize();
        v += (dv1 + dv2 * 2.0 + dv3 * 2.0 + dv4) * (H / 6.0);
        p += (dp1 + dp2 * 2.0 + dp3 * 2.0 + dp4) * (H / 6.0);

        let att = UnitQuaternion::from_quaternion(q).angle_to(&end.attitude);
        errors.attitude_rad = errors.attitude_rad.max(att);
        errors.velocity_mps = errors.velocity_mps.max((v - end.velocity_n).norm());
        errors.position_m = errors.position_m.max((p - path.position_n(t + H)).norm());
        prev = end;
    }
    errors
}

/// RK4 with h = 1 ms over the whole walk (~109 s), from the initial truth.
///
/// (a) On the simulator's own grid every lift-off and heel strike (3 s plus whole multiples of
/// 0.45 s and 0.6 s) falls on a grid point, so no step straddles a phase boundary and the
/// integrand is smooth within each step: the error is the O(h⁴) truncation, measured at ~1e-10 rad,
/// ~2e-8 m/s and ~1e-6 m. Asserted at 1e-8 rad, 1e-6 m/s and 1e-4 m (100× margin).
///
/// (b) On a grid offset by 0.37 ms each swing's first and last steps straddle a jump of the jerk
/// |Δj| = L(2π)²/T³ ≈ 240 m/s³ (the cycloid's acceleration is continuous, its derivative is not).
/// An RK4 step integrates a kinked acceleration with a velocity error of at most |Δj|·h²/24 ≈ 1e-5
/// m/s; the heel-strike jump is equal and opposite to the lift-off one at the same grid phase, so
/// the two cancel and at most one is live at a time: velocity ≤ 2e-5 m/s, position ≤ 2e-5 m/s ×
/// 109 s ≈ 2.2 mm, asserted at 2.5 mm (well inside the ~1 cm the walk's accuracy checks need). The
/// body rate is continuous with a continuous derivative; the jump of its second derivative,
/// ≤ 6Θ(2π/T)³ ≈ 2.4e3 rad/s³, costs at most that × h³/12 ≈ 2e-7 rad per straddled step, again
/// cancelling in pairs: attitude asserted at 1e-6 rad.
///
/// A wrong sign or a missing term (Euler-rate relation, lift acceleration, gravity) gives errors
/// of the order of the motion itself: ≥ 0.1 rad or ≥ 0.1 m within one stride.
#[test]
fn integrated_rates_and_specific_force_reproduce_the_truth() {
    let (traj, path, _) = walk(30.0);
    let on_grid = strapdown(&traj, &path, 0.0);
    let off_grid = strapdown(&traj, &path, 0.37e-3);
    for (label, e) in [("on grid", &on_grid), ("offset", &off_grid)] {
        eprintln!(
            "{label}: attitude {:e} rad, velocity {:e} m/s, position {:e} m",
            e.attitude_rad, e.velocity_mps, e.position_m
        );
    }
    assert!(on_grid.attitude_rad < 1e-8);
    assert!(on_grid.velocity_mps < 1e-6);
    assert!(on_grid.position_m < 1e-4);
    assert!(off_grid.attitude_rad < 1e-6);
    assert!(off_grid.velocity_mps < 2e-5);
    assert!(off_grid.position_m < 2.5e-3);
}

/// The truth of every 1 kHz sample, with the sample times where stance begins or ends.
struct Phases {
    samples: Vec<TruthState>,
    /// Times of the first sample of each stance (heel strike) or swing (lift-off) after the first.
    boundaries: Vec<f64>,
}

fn phases(traj: &Trajectory) -> Phases {
    let samples: Vec<TruthState> = grid(traj).map(|t| traj.sample(t)).collect();
    let boundaries = samples
        .windows(2)
        .filter(|w| w[0].stance != w[1].stance)
        .map(|w| w[1].time_s)
        .collect();
    Phases {
        samples,
        boundaries,
    }
}

/// Stance: velocity, acceleration and body rate exactly zero, the foot level on the floor, so the
/// accelerometers read exactly −g on the body z axis. Phases alternate 97 stances (the first and
/// last open-ended) with 96 swings of 0.6 s, 0.45 s apart.
///
/// Swing: the foot's peak speed is twice the mean stride speed, 2·(50/38 m)/0.6 s = 4.386 m/s (3–6
/// m/s is typical of a foot at mid-swing in normal walking). The peak body rate is the pitch rate
/// at mid-swing, (16/(3√3))·(π/T)·15° = 4.22 rad/s, raised to ~4.70 rad/s where a corner's yaw rate adds; it must stay
/// under the 300 °/s (5.24 rad/s) range of the default gyros. Rates and accelerations are
/// continuous: the largest analytic angular acceleration is ~116 rad/s² and jerk ~245 m/s³, so
/// between 1 ms samples the rate changes by < 0.15 rad/s and the acceleration by < 0.3 m/s²; a
/// step at a phase boundary would exceed both.
#[test]
fn foot_rests_exactly_in_stance_and_swings_plausibly() {
    let (traj, _, config) = walk(30.0);
    let p = phases(&traj);
    assert_eq!(p.boundaries.len(), 2 * walk::stride_count());
    for pair in p.boundaries.chunks(2) {
        assert!(
            (pair[1] - pair[0] - SWING_S).abs() < 1.5 * H,
            "swing {pair:?}"
        );
    }
    for gap in p.boundaries[1..].chunks(2).filter(|c| c.len() == 2) {
        assert!(
            (gap[1] - gap[0] - STANCE_S).abs() < 1.5 * H,
            "stance {gap:?}"
        );
    }
    assert!((p.boundaries[0] - config.static_s).abs() < 1e-9);

    let (mut peak_speed, mut peak_rate) = (0.0_f64, 0.0_f64);
    let (mut max_rate_step, mut max_accel_step) = (0.0_f64, 0.0_f64);
    for w in p.samples.windows(2) {
        let s = &w[1];
        max_rate_step = max_rate_step.max((s.angular_rate_b - w[0].angular_rate_b).norm());
        max_accel_step = max_accel_step.max((s.acceleration_n - w[0].acceleration_n).norm());
        if s.stance {
            assert_eq!(s.velocity_n, Vector3::zeros(), "t={}", s.time_s);
            assert_eq!(s.angular_rate_b, Vector3::zeros(), "t={}", s.time_s);
            assert_eq!(s.acceleration_n, Vector3::zeros(), "t={}", s.time_s);
            assert_eq!((s.euler_rad[0], s.euler_rad[1]), (0.0, 0.0));
            assert_eq!(s.altitude_m, config.origin_altitude_m);
            let level = Vector3::new(0.0, 0.0, -STANDARD_GRAVITY);
            assert!((s.specific_force_b - level).norm() < 1e-12);
        } else {
            peak_speed = peak_speed.max(s.velocity_n.norm());
            peak_rate = peak_rate.max(s.angular_rate_b.norm());
        }
    }
    let expected_speed = 2.0 * (COURSE_LENGTH_M / 38.0) / SWING_S;
    assert!(
        (peak_speed - expected_speed).abs() < 1e-6,
        "peak speed {peak_speed} m/s"
    );
    assert!(
        (4.2..=300f64.to_radians() * 0.95).contains(&peak_rate),
        "peak body rate {peak_rate} rad/s"
    );
    assert!(max_rate_step < 0.15, "rate step {max_rate_step} rad/s");
    assert!(
        max_accel_step < 0.3,
        "acceleration step {max_accel_step} m/s²"
    );
    // After the walk the foot stays at rest for good.
    for t in [traj.end_s(), traj.end_s() + 1e4] {
        let s = traj.sample(t);
        assert!(s.stance && s.velocity_n == Vector3::zeros());
        assert_eq!(s.foot_load, STANCE_LOAD);
    }
}

/// The load is exactly 0 in swing and STANCE_LOAD in stance farther than LOAD_RAMP_S from heel
/// strike and toe-off; within the ramps it lies strictly between, and within one sample of heel
/// strike it is below (1 − cos(π·1 ms/50 ms))/2 ≈ 1e-3. The swing of stride k spans
/// [3 s + k·1.05 s, 3 s + k·1.05 s + 0.6 s) by construction, and the `stance` flag must agree.
#[test]
fn foot_load_follows_the_stance_phases() {
    let (traj, _, config) = walk(0.0);
    let lift_offs: Vec<f64> = (0..walk::stride_count())
        .map(|k| config.static_s + k as f64 * STRIDE_PERIOD_S)
        .collect();
    let (mut plateau, mut ramp, mut heel_strikes) = (0, 0, 0);
    let mut was_in_swing = false;
    for t in grid(&traj) {
        let s = traj.sample(t);
        // The stride whose lift-off is the last one at or before t, and the next lift-off.
        let i = lift_offs.partition_point(|&l| l <= t);
        let touchdown = i
            .checked_sub(1)
            .map_or(f64::NEG_INFINITY, |j| lift_offs[j] + SWING_S);
        let next_lift_off = lift_offs.get(i).copied().unwrap_or(f64::INFINITY);
        let in_swing = t < touchdown;
        assert_eq!(s.stance, !in_swing, "t={t}");
        if in_swing {
            assert_eq!(s.foot_load, 0.0, "t={t}");
            was_in_swing = true;
            continue;
        }
        let (since, until) = (t - touchdown, next_lift_off - t);
        if since.min(until) >= LOAD_RAMP_S {
            assert_eq!(s.foot_load, STANCE_LOAD, "t={t}");
            plateau += 1;
        } else {
            // Within rounding of the ramp's end the load may already round to full.
            let full = STANCE_LOAD
                + if since.min(until) > LOAD_RAMP_S - 1e-9 {
                    1e-12
                } else {
                    0.0
                };
            assert!(
                (0.0..full).contains(&s.foot_load),
                "t={t} load {}",
                s.foot_load
            );
            ramp += 1;
        }
        if was_in_swing {
            assert!(since <= H * (1.0 + 1e-9), "t={t}");
            assert!(s.foot_load < 1e-3, "heel strike at t={t}: {}", s.foot_load);
            heel_strikes += 1;
        }
        was_in_swing = false;
    }
    assert_eq!(heel_strikes, walk::stride_count());
    assert!(plateau > 30_000 && ramp > 96 * 2 * 45, "{plateau} {ramp}");
}

/// The auxiliary frames carry the load in counts: foot_load·65535 plus 20 counts of noise, so
/// within 6σ = 120 counts of the truth (clamped at 0 in swing); ~52 428 counts in stance.
#[test]
fn simulator_foot_pressure_frames_follow_the_load() {
    let config = walk_config(0.0, 3.0);
    let axes = optimal_pyramid_axes();
    let mut sim = Simulator::new(&config, &axes, &axes, 5).unwrap();
    let sigma = config.sensors.foot_pressure_noise_counts;
    assert_eq!(sigma, 20.0);
    let mut out = TickOutput::default();
    let (mut stance_frames, mut swing_frames) = (0, 0);
    while sim.time_s() < sim.trajectory().end_s() + 1.0 {
        sim.step(&mut out);
        let Some(frame) = out.frame(FrameType::Aux) else {
            continue;
        };
        let Payload::Aux(aux) = frame.payload else {
            panic!("not an aux frame")
        };
        let truth = sim
            .trajectory()
            .sample(out.truth.device_time_us as f64 * 1e-6);
        let expected = truth.foot_load * f64::from(u16::MAX);
        let counts = f64::from(aux.foot_pressure);
        assert!(
            (counts - expected).abs() <= 6.0 * sigma,
            "t={} counts {counts} expected {expected}",
            truth.time_s
        );
        if truth.foot_load == STANCE_LOAD {
            stance_frames += 1;
        } else if !truth.stance {
            swing_frames += 1;
        }
    }
    // 100 Hz over ~109 s: about 57 s of full-load stance and 57.6 s of swing.
    assert!(
        stance_frames > 4000 && swing_frames > 5000,
        "{stance_frames} {swing_frames}"
    );
}

#[test]
fn walk_parses_from_toml_and_builds() {
    let c: SimConfig = toml::from_str("scenario = \"walk\"\nstatic_s = 2.0\n").unwrap();
    c.validate().unwrap();
    assert_eq!(c.scenario, Scenario::Walk);
    let axes = optimal_pyramid_axes();
    let sim = Simulator::new(&c, &axes, &axes, 1).unwrap();
    assert_eq!(sim.trajectory().lift_off_s(), 2.0);
    assert!(sim.trajectory().end_s() > 100.0);
}

/// Outside the walk the load is 0 and `stance` marks rest: always when static; before take-off
/// and after the landing roll for the UAV.
#[test]
fn other_scenarios_have_no_load_and_stance_means_parked() {
    let config = SimConfig::default();
    let still = Trajectory::new(Scenario::Static, config.trajectory_start());
    let uav = Trajectory::new(Scenario::Uav, config.trajectory_start());
    for t in [0.0, 1.0, 100.0, 1e4] {
        let s = still.sample(t);
        assert!(s.stance && s.foot_load == 0.0);
    }
    for (t, parked) in [
        (0.0, true),
        (config.static_s, true),
        (config.static_s + 0.01, false),
        (uav.touchdown_s(), false),
        (uav.end_s() - 0.01, false),
        (uav.end_s(), true),
        (uav.end_s() + 100.0, true),
    ] {
        let s = uav.sample(t);
        assert_eq!(s.stance, parked, "t={t}");
        assert_eq!(s.foot_load, 0.0);
        if parked {
            assert_eq!(s.velocity_n, Vector3::zeros());
        }
    }
}

#[test]
fn sampling_the_walk_does_not_allocate() {
    let (traj, _, _) = walk(0.0);
    let mut checksum = 0.0;
    let allocations = allocations_during(|| {
        for t in grid(&traj) {
            checksum += traj.sample(t).foot_load;
        }
    });
    assert_eq!(allocations, 0);
    assert!(checksum > 0.0);
}
