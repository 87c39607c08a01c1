//! The MAVLink output as a ground station sees it: pymavlink receives the stream of a running
//! pipeline and checks the message set, the rates, the attitude and covariance against the
//! solution, TIMESYNC, a refused command, the STATUSTEXT of a dead gyro and the reset counter of a
//! killed navigator lane, and re-admission commands acknowledged with fusion's answer
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
    let out = run_script(
        &python,
        &ipc,
        "python/tests/mavlink_stream.py",
        &[RINS, &port],
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
    assert!(ipc.shm_entries().is_empty(), "{:?}", ipc.shm_entries());
}
