//! The whole pipeline as real processes: simulator on a pseudo-terminal, acquisition, fusion,
//! altimeter, navigator and watchdog over iceoryx2, checked against simulator truth.

mod common;

use common::{Isolated, last_json, num};

/// Runs `rins up` for `duration` seconds and returns the summary, after checking a clean exit and
/// an empty /dev/shm for the test's prefix.
fn up(test: &str, scenario: &str, duration: &str) -> serde_json::Value {
    up_with(test, &["--scenario", scenario, "--duration", duration])
}

/// `rins up ARGS --json`, checked as [`up`] does.
fn up_with(test: &str, args: &[&str]) -> serde_json::Value {
    let ipc = Isolated::new(test);
    let mut all = vec!["up"];
    all.extend_from_slice(args);
    all.push("--json");
    let out = ipc.run(&all);
    assert!(
        out.status.success(),
        "rins up failed: {:?}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = last_json(&out);
    assert_eq!(
        ipc.shm_entries(),
        Vec::<String>::new(),
        "shared memory left behind"
    );
    assert_eq!(num(&summary, "shm_leaked"), 0.0);
    assert!(
        !ipc.root.exists(),
        "iceoryx2 root left behind: {}",
        ipc.root.display()
    );
    summary
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
}
