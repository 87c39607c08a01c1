//! The whole pipeline as real processes: simulator on a pseudo-terminal, acquisition, fusion,
//! altimeter, navigator and watchdog over iceoryx2, checked against simulator truth.

mod common;

use common::{num, up_json as up_with};

/// Runs `rins up` for `duration` seconds and returns the summary, after checking a clean exit and
/// an empty /dev/shm for the test's prefix.
fn up(test: &str, scenario: &str, duration: &str) -> serde_json::Value {
    up_with(test, &["--scenario", scenario, "--duration", duration])
}

#[test]
fn static_scenario_keeps_attitude_and_drops_nothing() {
    let s = up("static", "static", "6");
    // 1 kHz for ~6 s, minus start-up.
    assert!(num(&s, "frames") > 5_000.0, "{s}");
    common::assert_no_loss_beyond_the_line(&s);
    assert_eq!(num(&s, "crc_errors"), 0.0, "{s}");
    assert_eq!(num(&s, "restarts"), 0.0, "{s}");
    // Static: alignment error from the accelerometer noise and bias (5 mg ≈ 0.3°) plus the
    // quantisation of the averaged signal; the design target is 0.5°.
    assert!(num(&s, "att_err_deg_max") < 0.5, "{s}");
    // Baro noise 2 Pa ≈ 0.17 m per sample, filtered.
    assert!(num(&s, "alt_err_m_rms") < 1.0, "{s}");
}

#[test]
fn uav_scenario_tracks_attitude_and_altitude_through_take_off() {
    // 25 s covers the ground roll, the take-off and the start of the climb.
    let s = up("uav", "uav", "25");
    assert!(num(&s, "frames") > 20_000.0, "{s}");
    common::assert_no_loss_beyond_the_line(&s);
    assert!(num(&s, "att_err_deg_rms") < 2.0, "{s}");
    assert!(num(&s, "alt_err_m_rms") < 5.0, "{s}");
}

#[test]
fn pedestrian_profile_walks_with_zero_velocity_and_heading_updates() {
    // The built-in walk: 3 s standing, then strides of 1.05 s; 20 s covers 16 of them. The
    // pedestrian profile's filter, with ZUPT in every stance and HUPT, holds the attitude to the
    // tilt/heading coupling of the stance phases (measured 1.5° RMS, 2.4° max over the whole
    // 112 s walk).
    let profile = concat!(env!("CARGO_MANIFEST_DIR"), "/config/pedestrian.toml");
    let s = up_with(
        "walk",
        &[
            "--config",
            profile,
            "--scenario",
            "walk",
            "--duration",
            "20",
        ],
    );
    assert!(num(&s, "frames") > 15_000.0, "{s}");
    common::assert_no_loss_beyond_the_line(&s);
    assert!(num(&s, "att_err_deg_max") < 3.0, "{s}");
    assert!(num(&s, "alt_err_m_rms") < 1.0, "{s}");
    assert_walk_figures(&s);
}

/// The walk's horizontal figures: the distance is what the built-in walk covers in the run's
/// device time (3 s standing, then one stride of 50/38 m every 1.05 s along the first side), and
/// the share is the end-point error over that distance.
fn assert_walk_figures(s: &serde_json::Value) {
    use rins_sim::trajectory::walk::{COURSE_LENGTH_M, STRIDE_PERIOD_S, strides_per_side};
    let distance = num(s, "distance_m");
    let err = num(s, "horiz_end_err_m");
    let pct = num(s, "horiz_end_err_pct");
    assert!((pct - 100.0 * err / distance).abs() < 1e-9, "{s}");
    let stride = COURSE_LENGTH_M / strides_per_side(COURSE_LENGTH_M) as f64;
    // The simulator's device time lies between the frames the watchdog counted (1 kHz; it
    // subscribed a little after the simulator began) and the run's wall time (the simulator
    // started after the watchdog); a stride more on either side for the stride in progress and
    // where the alignment ended.
    let strides_by = |t: f64| (t - 3.0) / STRIDE_PERIOD_S;
    let fewest = strides_by(num(s, "frames") / 1000.0).floor() - 1.0;
    let most = strides_by(num(s, "duration_s")).ceil() + 1.0;
    assert!(
        distance > fewest * stride && distance < most * stride,
        "{distance} m, expected {fewest}..{most} strides of {stride} m: {s}"
    );
    // A foot-mounted filter with ZUPT and HUPT: metres, not tens of metres, after ~20 m.
    assert!(err < 5.0, "{s}");
}
