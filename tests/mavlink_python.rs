//! The MAVLink output as a ground station sees it: pymavlink receives the stream of a running
//! pipeline and checks the message set, the rates, the attitude and covariance against the
//! solution, TIMESYNC, a refused command, the STATUSTEXT of a dead gyro and the reset counter of a
//! killed navigator lane (the one delivering), and re-admission commands acknowledged with fusion's answer
//! (python/tests/mavlink_stream.py says how each is checked).

mod common;

use common::python::{free_udp_port, interpreter, run_script};
use common::{Isolated, PipelineSlot, RINS, TempFile};

#[test]
fn pymavlink_receives_the_stream_a_pipeline_sends() {
    let Some(python) = interpreter("pymavlink_receives_the_stream_a_pipeline_sends") else {
        return;
    };
    let ipc = Isolated::new("mavpy");
    let _slot = PipelineSlot::take();
    let port = free_udp_port().to_string();
    // The built-in configuration, taking commands from the link.
    let accepting =
        rins::config::BUILT_IN.replace("accept_commands = false", "accept_commands = true");
    assert_ne!(accepting, rins::config::BUILT_IN);
    let config = TempFile::new("mavpy", "toml", &accepting);
    let out = run_script(
        &python,
        &ipc,
        "python/tests/mavlink_stream.py",
        &[RINS, &port, config.path()],
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
    assert!(ipc.shm_entries().is_empty(), "{:?}", ipc.shm_entries());
}
