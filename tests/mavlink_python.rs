//! The MAVLink output as a ground station sees it: pymavlink receives the stream of a running
//! pipeline and checks the message set, the rates, the attitude and covariance against the
//! solution, TIMESYNC, a refused command, the STATUSTEXT of a dead gyro and the reset counter of a
//! killed navigator lane (the one delivering), and re-admission commands acknowledged with fusion's answer
//! (python/tests/mavlink_stream.py says how each is checked). The link is signed: pymavlink checks
//! every signature rins sends with the shared key, signs what it sends, and an unsigned command
//! is not answered.

mod common;

use common::python::{free_udp_port, interpreter, run_script};
use common::{Isolated, PipelineSlot, RINS, TempFile};

/// The shared MAVLink 2 signing key, as its file holds it.
const KEY_HEX: &str = "8f3c1d2e4b5a69788796a5b4c3d2e1f00f1e2d3c4b5a69788796a5b4c3d2e1f0";

#[test]
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
