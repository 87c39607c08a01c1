//! An interactive `rins up` (no `--duration`) stopped by Ctrl-C ends with the same summary a timed
//! run prints, text or JSON, and exits 0 with no shared memory left.

mod common;

use std::time::Duration;

use common::{Isolated, PipelineSlot, last_json, spawn_up};

/// How long the pipeline runs before the interrupt: enough for the simulator to stream frames.
const RUN_BEFORE_INTERRUPT: Duration = Duration::from_secs(4);

/// Starts `rins up ARGS` without a duration, interrupts it as Ctrl-C does and returns its output.
fn interrupted(test: &str, args: &[&str]) -> (Isolated, std::process::Output) {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new(test);
    let up = spawn_up(&ipc, args);
    std::thread::sleep(RUN_BEFORE_INTERRUPT);
    let pid = libc::pid_t::try_from(up.id()).expect("pid fits pid_t");
    // SAFETY: kill(2) on our own child, not reaped yet, with a valid signal number.
    assert_eq!(unsafe { libc::kill(pid, libc::SIGINT) }, 0);
    let out = up.wait_with_output().expect("rins up did not finish");
    assert_eq!(
        out.status.code(),
        Some(0),
        "rins up after SIGINT: {:?}\n{}",
        out.status,
        ipc.up_stderr()
    );
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
    (ipc, out)
}

#[test]
fn ctrl_c_on_an_interactive_run_prints_the_text_summary() {
    let (ipc, out) = interrupted("interactive_text", &["--scenario", "static"]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with("summary: "))
        .unwrap_or_else(|| panic!("no summary in {stdout:?}\n{}", ipc.up_stderr()));
    assert!(
        line.contains("IMU frames") && line.contains("shared-memory entries left"),
        "{line}"
    );
    // The run lasted about as long as it was let run (start-up is slow on a loaded machine).
    let seconds: f64 = line["summary: ".len()..]
        .split(' ')
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no duration in {line}"));
    assert!(
        seconds > 0.0 && seconds < RUN_BEFORE_INTERRUPT.as_secs_f64() + 2.0,
        "{line}"
    );
}

#[test]
fn ctrl_c_on_an_interactive_json_run_prints_the_json_summary() {
    let (_ipc, out) = interrupted("interactive_json", &["--scenario", "static", "--json"]);
    let summary = last_json(&out);
    assert!(
        summary["duration_s"].as_f64().unwrap_or(0.0) > 0.0,
        "{summary}"
    );
    assert_eq!(summary["shm_leaked"], 0, "{summary}");
}
