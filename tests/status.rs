//! `rins status` against a running pipeline, and what it shows when a service is killed with a
//! real SIGKILL: the watchdog restarts it and the report counts the restart under a new pid.

mod common;

use std::time::Duration;

use common::{Isolated, PipelineSlot, TempFile, spawn_up, spawn_up_navigating, stop_up};
use rins_test_support::signal::{Signal, process_exists, send_signal};
use serde_json::Value;

fn service<'a>(report: &'a Value, name: &str) -> &'a Value {
    report["services"]
        .as_array()
        .expect("services array")
        .iter()
        .find(|s| s["service"] == name)
        .unwrap_or_else(|| panic!("no {name} in {report}"))
}

#[test]
fn status_shows_every_process_and_counts_a_restart_after_sigkill() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("status");
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "300", "--json"],
    );

    let names = [
        "watchdog",
        "acquisition",
        "fusion",
        "altimeter",
        "navigator",
        "sim",
    ];
    let report = ipc.status_until(Duration::from_secs(20), |r| {
        names.iter().all(|n| service(r, n)["state"] == "running")
    });
    for name in names {
        let s = service(&report, name);
        assert_eq!(s["restarts"], 0, "{s}");
        assert!(s["pid"].as_u64().unwrap() > 0, "{s}");
        // Heartbeats come once a second.
        assert!(s["heartbeat_age_ms"].as_u64().unwrap() < 3000, "{s}");
    }
    // 1 kHz input: the navigator and fusion publish every sample. The report's window is 250 ms,
    // so a busy machine may shift samples between windows: a stage held off the CPU for 130 ms of
    // the window (seen at a load of 4 on 2 cores) reads half the rate. What is checked is that
    // output flows at the input's order of magnitude, not 0 and not a burst of several windows.
    for name in ["fusion", "navigator"] {
        let rate = service(&report, name)["output_rate_hz"].as_f64().unwrap();
        assert!((250.0..=1750.0).contains(&rate), "{name} {rate}");
    }
    assert!(service(&report, "sim")["output_rate_hz"].is_null());

    // A real SIGKILL to fusion: the watchdog restarts it, the report shows the new pid and the
    // restart, and navigation output resumes.
    let old_pid = service(&report, "fusion")["pid"].as_u64().unwrap();
    // A process of this test's own pipeline.
    send_signal(old_pid, Signal::Kill).expect("SIGKILL");
    let after = ipc.status_until(Duration::from_secs(20), |r| {
        let f = service(r, "fusion");
        f["restarts"] == 1 && f["state"] == "running"
    });
    let fusion = service(&after, "fusion");
    assert_ne!(fusion["pid"].as_u64().unwrap(), old_pid, "{fusion}");
    for name in ["acquisition", "altimeter", "navigator", "sim"] {
        assert_eq!(service(&after, name)["restarts"], 0, "{name}: {after}");
    }
    let again = ipc.run(&["echo", "nav", "--count", "5", "--timeout", "30"]);
    assert!(again.status.success());

    let summary = stop_up(&ipc, up);
    assert_eq!(summary["restarts"], 1, "{summary}");
}

#[test]
fn status_without_a_pipeline_fails_naming_the_prefix() {
    let ipc = Isolated::new("status_none");
    let out = ipc.run(&["status", "--timeout", "0.5"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no health report") && err.contains(&ipc.prefix),
        "{err}"
    );
}

/// Runs a static pipeline with `watchdog` as its `[watchdog]` settings, SIGSTOPs `name` once it
/// runs, and checks that the watchdog replaced it — a new pid, the stopped process gone, no other
/// service restarted, navigation going on — before `limit`; then stops the pipeline cleanly.
fn stopped_service_is_replaced(test: &str, watchdog: &str, name: &str, limit: Duration) {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new(test);
    let config = TempFile::new(test, "toml", &format!("[watchdog]\n{watchdog}"));
    let up = spawn_up_navigating(
        &ipc,
        &[
            "--config",
            config.path(),
            "--scenario",
            "static",
            "--duration",
            "300",
            "--json",
        ],
    );
    let report = ipc.status_until(Duration::from_secs(60), |r| {
        service(r, name)["state"] == "running"
    });
    let old_pid = service(&report, name)["pid"].as_u64().unwrap();
    // SIGSTOP: the process is still there but does nothing, as if hung.
    send_signal(old_pid, Signal::Stop).expect("SIGSTOP");
    let after = ipc.status_until(limit, |r| {
        let s = service(r, name);
        s["restarts"] == 1 && s["state"] == "running"
    });
    assert_ne!(service(&after, name)["pid"].as_u64().unwrap(), old_pid);
    // The stopped process is gone (killed and reaped: no zombie under the old pid).
    assert!(!process_exists(old_pid), "pid {old_pid} still exists");
    let others = [
        "acquisition",
        "fusion",
        "altimeter",
        "navigator",
        "navigator-standby",
    ];
    for other in others.into_iter().filter(|&o| o != name) {
        assert_eq!(service(&after, other)["restarts"], 0, "{other}: {after}");
    }
    let again = ipc.run(&["echo", "nav", "--count", "5", "--timeout", "30"]);
    assert!(again.status.success());
    assert_eq!(stop_up(&ipc, up)["restarts"], 1);
}

#[test]
fn a_stopped_service_is_seen_silent_killed_and_restarted() {
    // The heartbeat path alone (the output deadline would replace the navigator sooner): its
    // heartbeat stops, and after the 3 s timeout the watchdog kills and restarts it.
    stopped_service_is_replaced(
        "hang",
        "output_deadline_s = 0\n",
        "navigator",
        Duration::from_secs(30),
    );
}

#[test]
fn a_stage_that_stops_answering_its_input_is_replaced_by_its_output_deadline() {
    // Raw IMU samples go on arriving, fused ones stop. Heartbeats would take ten minutes to call
    // it hung: only the output deadline can act within the limit.
    stopped_service_is_replaced(
        "deadline",
        "heartbeat_timeout_s = 600\noutput_deadline_s = 0.5\n",
        "fusion",
        Duration::from_secs(20),
    );
}

#[test]
fn fusion_says_when_acquisition_goes_quiet_and_when_it_is_back() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("stale");
    let up = spawn_up(
        &ipc,
        &["--scenario", "static", "--duration", "300", "--json"],
    );
    let report = ipc.status_until(Duration::from_secs(60), |r| {
        service(r, "acquisition")["state"] == "running"
            && service(r, "fusion")["state"] == "running"
    });
    assert_eq!(service(&report, "fusion")["input_stale"], false);
    let pid = service(&report, "acquisition")["pid"].as_u64().unwrap();
    // Acquisition stopped: fusion's input deadline (50 ms) passes and its next heartbeat (within
    // a second) says so; after the 3 s heartbeat timeout the watchdog replaces acquisition and
    // fusion's input returns.
    send_signal(pid, Signal::Stop).expect("SIGSTOP");
    ipc.status_until(Duration::from_secs(10), |r| {
        service(r, "fusion")["input_stale"] == true
    });
    ipc.status_until(Duration::from_secs(30), |r| {
        let a = service(r, "acquisition");
        a["restarts"] == 1
            && a["state"] == "running"
            && service(r, "fusion")["input_stale"] == false
    });
    let heartbeat = ipc.run(&[
        "echo",
        "heartbeat",
        "--raw",
        "--count",
        "20",
        "--timeout",
        "10",
    ]);
    assert!(heartbeat.status.success());
    let text = String::from_utf8_lossy(&heartbeat.stdout);
    let fusion_episodes = text
        .lines()
        .filter_map(|l| serde_json::from_str::<Value>(l).ok())
        .filter(|h| h["service"] == 2)
        .map(|h| h["stale_input_episodes"].as_u64().unwrap())
        .max();
    assert!(fusion_episodes.is_some_and(|n| n >= 1), "{text}");

    stop_up(&ipc, up);
}

/// While the serial line is unplugged no navigation sample comes: the report and the status line
/// say so instead of the last sample's "navigating", and say navigating again once it flows.
#[test]
fn a_navigation_output_that_stops_is_not_reported_as_navigating() {
    let ipc = Isolated::new("navstops");
    let _slot = PipelineSlot::take();
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "60", "--json"],
    );
    // Aligned and flowing first.
    ipc.status_until(Duration::from_secs(30), |r| {
        r["navigation"]["mode"] == "navigating" && r["navigation"]["output_flowing"] == true
    });
    let out = ipc.run(&["inject", "disconnect", "--duration", "4"]);
    assert!(out.status.success(), "{}", common::stderr(&out));
    let stopped = ipc.status_until(Duration::from_secs(10), |r| {
        r["navigation"]["output_flowing"] == false
    });
    let nav = &stopped["navigation"];
    assert_eq!(nav["mode"], "invalid", "{stopped}");
    assert!(
        nav["summary"]
            .as_str()
            .is_some_and(|s| s.starts_with("no navigation output for ")),
        "{stopped}"
    );
    let start = std::time::Instant::now();
    while !ipc.up_stderr().contains("| no navigation output") {
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "no status line said so:\n{}",
            ipc.up_stderr()
        );
        std::thread::sleep(Duration::from_millis(100));
    }
    ipc.status_until(Duration::from_secs(30), |r| {
        r["navigation"]["output_flowing"] == true
    });
    stop_up(&ipc, up);
}
