//! Lost redundancy is seen where an operator looks, and a re-admission says what became of it:
//! a gyro killed with `rins inject` shows up excluded, with its reason, in `rins status --json`
//! and in the watchdog's status line; `rins readmit` is refused while the fault is present, and
//! succeeds once it is gone.

mod common;

use std::io::{BufRead, BufReader};
use std::process::Stdio;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, stderr};
use rins_test_support::signal::{Signal, send_signal};
use serde_json::Value;

/// The channel's row in the status report's channel table.
fn channel<'a>(report: &'a Value, name: &str) -> &'a Value {
    report["redundancy"]["channels"]
        .as_array()
        .unwrap_or_else(|| panic!("no channel table in {report}"))
        .iter()
        .find(|c| c["channel"] == name)
        .unwrap_or_else(|| panic!("no {name} in {report}"))
}

/// Waits for a status line on `lines` that contains `text`.
fn wait_for_line(lines: &mpsc::Receiver<String>, text: &str, limit: Duration) -> String {
    let deadline = Instant::now() + limit;
    let mut last = String::new();
    while Instant::now() < deadline {
        if let Ok(line) = lines.recv_timeout(Duration::from_millis(100)) {
            if line.starts_with("t=") && line.contains(text) {
                return line;
            }
            last = line;
        }
    }
    panic!("no status line with {text:?} within {limit:?}; last line: {last}");
}

#[test]
fn a_killed_gyro_is_seen_excluded_and_readmit_reports_its_outcome() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("redundancy");
    let mut up = ipc
        .command()
        .args(["up", "--scenario", "static", "--duration", "300"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start rins up");
    let stdout = up.stdout.take().expect("piped stdout");
    let (tx, lines) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });

    // Every channel in use, the solution navigating.
    let healthy = ipc.status_until(Duration::from_secs(120), |r| {
        r["navigation"]["mode"] == "navigating" && r["redundancy"]["gyro"]["in_use"] == 4
    });
    assert_eq!(healthy["redundancy"]["accel"]["in_use"], 4, "{healthy}");
    assert_eq!(healthy["redundancy"]["summary"], "gyro 4/4 accel 4/4");
    // Either lane may be the one in use: both run the same filter, the first to align serves.
    let lane = healthy["navigation"]["lane"].as_u64().expect("a lane");
    assert!(lane <= 1, "{healthy}");
    assert_eq!(channel(&healthy, "gyro2")["state"], "ok");
    wait_for_line(
        &lines,
        "| gyro 4/4 accel 4/4 | navigating",
        Duration::from_secs(10),
    );

    let out = ipc.run_with_timeout(&["inject", "gyro2", "dead"], Duration::from_secs(10));
    assert!(out.status.success(), "inject failed:\n{}", stderr(&out));
    let excluded = ipc.status_until(Duration::from_secs(10), |r| {
        channel(r, "gyro2")["state"] == "excluded"
    });
    assert_eq!(
        channel(&excluded, "gyro2")["reason"],
        "missing",
        "{excluded}"
    );
    assert_eq!(excluded["redundancy"]["gyro"]["in_use"], 3, "{excluded}");
    assert_eq!(
        excluded["redundancy"]["gyro"]["solution"], true,
        "{excluded}"
    );
    assert_eq!(channel(&excluded, "gyro1")["state"], "ok", "{excluded}");
    assert_eq!(excluded["navigation"]["mode"], "navigating", "{excluded}");
    wait_for_line(
        &lines,
        "| gyro 3/4 (gyro2 missing) accel 4/4 |",
        Duration::from_secs(10),
    );

    // Still dead: fusion takes the channel back, sees it missing again, and refuses.
    let out = ipc.run_with_timeout(&["readmit", "gyro2"], Duration::from_secs(20));
    assert!(
        !out.status.success(),
        "a readmit of a dead channel must fail"
    );
    assert!(
        stderr(&out).contains("gyro2: refused: excluded again during its probation (missing)"),
        "{}",
        stderr(&out)
    );
    // The block has 4 gyros: fusion refuses gyro9.
    let out = ipc.run_with_timeout(&["readmit", "gyro9"], Duration::from_secs(20));
    assert!(!out.status.success());
    assert!(stderr(&out).contains("no such channel"), "{}", stderr(&out));
    // A channel in service: nothing to do, and that is no failure.
    let out = ipc.run_with_timeout(&["readmit", "gyro1"], Duration::from_secs(20));
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(String::from_utf8_lossy(&out.stdout).contains("gyro1: not excluded"));

    // The fault gone, the channel returns and stays through its probation.
    let out = ipc.run_with_timeout(&["inject", "gyro2", "clear"], Duration::from_secs(10));
    assert!(out.status.success(), "clear failed:\n{}", stderr(&out));
    let out = ipc.run_with_timeout(&["readmit", "gyro2"], Duration::from_secs(20));
    assert!(out.status.success(), "readmit failed:\n{}", stderr(&out));
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("gyro2: readmitted"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let back = ipc.status_until(Duration::from_secs(10), |r| {
        channel(r, "gyro2")["state"] == "ok"
    });
    assert_eq!(back["redundancy"]["gyro"]["in_use"], 4, "{back}");
    wait_for_line(&lines, "| gyro 4/4 accel 4/4 |", Duration::from_secs(10));

    // Stopped as an operator does; nothing left in shared memory.
    send_signal(u64::from(up.id()), Signal::Terminate).expect("SIGTERM to our own child");
    let status = up.wait().expect("rins up did not finish");
    assert!(status.success(), "rins up: {status}");
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}
