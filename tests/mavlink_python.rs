//! The MAVLink output as a ground station sees it: pymavlink receives the stream of a running
//! pipeline and checks the message set, the rates, the attitude and covariance against the
//! solution, TIMESYNC, a refused command, the STATUSTEXT of a dead gyro and the reset counter of a
//! killed navigator lane (the one delivering), and re-admission commands acknowledged with fusion's answer
//! (python/tests/mavlink_stream.py says how each is checked). The link is signed: pymavlink checks
//! every signature rins sends with the shared key, signs what it sends, and an unsigned command
//! is not answered. Then, for each `[mavlink] autopilot`, the ODOMETRY frames and quality and the
//! global origin announcement (python/tests/mavlink_autopilot.py).

mod common;

use common::python::{free_udp_port, interpreter, run_script};
use common::{Isolated, PipelineSlot, RINS, TempFile};

/// The shared MAVLink 2 signing key, as its file holds it.
const KEY_HEX: &str = "8f3c1d2e4b5a69788796a5b4c3d2e1f00f1e2d3c4b5a69788796a5b4c3d2e1f0";

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn pymavlink_receives_the_stream_a_pipeline_sends() {
    let Some(python) = interpreter("pymavlink_receives_the_stream_a_pipeline_sends") else {
        return;
    };
    let ipc = Isolated::new("mavpy");
    let _slot = PipelineSlot::take();
    let port = free_udp_port().to_string();
    // The key file, private as rins requires.
    let key = TempFile::new("mavpy", "key", &format!("{KEY_HEX}\n"));
    std::fs::set_permissions(
        key.path(),
        std::os::unix::fs::PermissionsExt::from_mode(0o600),
    )
    .expect("cannot make the key file private");
    // The built-in configuration, taking signed commands from the test's ground station.
    let accepting = rins::config::BUILT_IN
        .replace("accept_commands = false", "accept_commands = true")
        .replace(
            "# signing_key_file = \"/etc/rins/mavlink.key\"",
            &format!("signing_key_file = {:?}", key.path()),
        )
        .replace(
            "command_sources = []",
            "command_sources = [{ system = 255 }]",
        );
    assert!(accepting.contains("accept_commands = true"));
    assert!(accepting.contains("\nsigning_key_file = "));
    assert!(accepting.contains("command_sources = [{ system = 255 }]"));
    let config = TempFile::new("mavpy", "toml", &accepting);
    let out = run_script(
        &python,
        &ipc,
        "python/tests/mavlink_stream.py",
        &[RINS, &port, config.path(), KEY_HEX],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "mavlink_stream.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let measured: serde_json::Value =
        serde_json::from_str(stdout.lines().last().unwrap_or("{}")).expect("a JSON line");
    eprintln!("{measured}");
    assert!(
        measured["odometry_exact_of_matched"][1]
            .as_u64()
            .unwrap_or(0)
            >= 10
    );
    // MAV_RESULT_IN_PROGRESS (5), then ACCEPTED (0) for a channel in service, FAILED (4) for one
    // still dead.
    assert_eq!(measured["readmit_in_service"], serde_json::json!([5, 0]));
    assert_eq!(measured["readmit_dead"], serde_json::json!([5, 4]));
    assert_eq!(
        measured["unsigned_command_answered"],
        serde_json::json!(false)
    );
    assert!(ipc.shm_entries().is_empty(), "{:?}", ipc.shm_entries());
}

/// Runs python/tests/mavlink_autopilot.py against a pipeline whose ODOMETRY is shaped for
/// `autopilot` (with a GNSS receiver when `gnss`), and returns what it measured.
fn autopilot_run(test: &str, autopilot: &str, gnss: bool) -> Option<serde_json::Value> {
    let python = interpreter(test)?;
    let ipc = Isolated::new("mavap");
    let _slot = PipelineSlot::take();
    let port = free_udp_port().to_string();
    let shaped = rins::config::BUILT_IN.replace(
        "\nautopilot = \"generic\"",
        &format!("\nautopilot = {autopilot:?}"),
    );
    assert!(shaped.contains(&format!("\nautopilot = {autopilot:?}")));
    let config = TempFile::new("mavap", "toml", &shaped);
    let mut args = vec![RINS, &port, config.path(), autopilot];
    if gnss {
        args.push("--gnss");
    }
    let out = run_script(&python, &ipc, "python/tests/mavlink_autopilot.py", &args);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "mavlink_autopilot.py {autopilot} failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(ipc.shm_entries().is_empty(), "{:?}", ipc.shm_entries());
    let measured: serde_json::Value =
        serde_json::from_str(stdout.lines().last().unwrap_or("{}")).expect("a JSON line");
    eprintln!("{measured}");
    Some(measured)
}

/// Without GNSS the solution is free-inertial: its horizontal σ passes σ₀ = 10 m and the quality
/// falls below 50 (the script checks every message's quality against its own covariance).
fn assert_free_inertial_quality_fell(measured: &serde_json::Value) {
    let seen = &measured["seen"];
    assert!(seen["above_sigma0"].as_u64().unwrap_or(0) >= 30, "{seen}");
    assert!(seen["sigma"][1].as_f64().unwrap_or(0.0) > 10.0, "{seen}");
    assert!(seen["quality"][0].as_i64().unwrap_or(100) < 50, "{seen}");
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn generic_odometry_is_local_ned_and_announces_no_origin() {
    let Some(m) = autopilot_run("generic_odometry", "generic", false) else {
        return;
    };
    assert_free_inertial_quality_fell(&m);
    assert!(m.get("origin").is_none(), "{m}");
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn px4_odometry_is_local_ned_with_the_origin_in_set_gps_global_origin() {
    let Some(m) = autopilot_run("px4_odometry", "px4", false) else {
        return;
    };
    assert_free_inertial_quality_fell(&m);
    assert_eq!(m["origin_kind"], "SET_GPS_GLOBAL_ORIGIN");
    // The configured initial position (the simulator's origin).
    assert_eq!(m["origin"][0], 47.397742);
    assert_eq!(m["origin"][1], 8.545594);
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn px4_odometry_with_gnss_keeps_its_quality_and_announces_the_origin() {
    let Some(m) = autopilot_run("px4_odometry_gnss", "px4", true) else {
        return;
    };
    // GNSS holds σ_h within σ₀: quality stays at 50 or more (the script fails on any σ_h > 10 m).
    assert!(m["seen"]["quality"][0].as_i64().unwrap_or(0) >= 50, "{m}");
    assert_eq!(m["origin_kind"], "SET_GPS_GLOBAL_ORIGIN");
    assert!(
        m["origin_plus_local_m"]["within_5cm"]
            .as_f64()
            .unwrap_or(0.0)
            >= 0.9
    );
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn ardupilot_odometry_is_local_frd_with_the_origin_in_a_command() {
    let Some(m) = autopilot_run("ardupilot_odometry", "ardupilot", false) else {
        return;
    };
    assert_free_inertial_quality_fell(&m);
    // Nothing to show is never sent to ArduPilot.
    assert_eq!(m["seen"]["invalid"], 0, "{m}");
    assert_eq!(m["origin_kind"], "COMMAND_INT");
    assert_eq!(m["origin"][0], 47.397742);
}
