//! Restart limits with real SIGKILLs: a service that dies more often than its limit allows is given
//! up — left down while the rest navigates, or the whole pipeline stopped with an error naming it.

mod common;

use std::time::{Duration, Instant};

use common::{Isolated, PipelineSlot, TempFile, fails_with, spawn_up_navigating, stderr, stop_up};
use rins_test_support::signal::{Signal, send_signal};
use serde_json::Value;

fn service(report: &Value, name: &str) -> Value {
    report["services"]
        .as_array()
        .expect("services")
        .iter()
        .find(|s| s["service"] == name)
        .cloned()
        .unwrap_or_else(|| panic!("no {name} in {report}"))
}

/// Waits until `name` runs (a new pid after `not`) and returns its pid.
fn running_pid(ipc: &Isolated, name: &str, not: Option<u64>) -> u64 {
    let start = Instant::now();
    loop {
        let s = service(&ipc.status(), name);
        let pid = s["pid"].as_u64().unwrap_or(0);
        if s["state"] == "running" && Some(pid) != not {
            return pid;
        }
        assert!(start.elapsed() < Duration::from_secs(30), "{name}: {s}");
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn sigkill(pid: u64) {
    // A process of this test's own pipeline.
    send_signal(pid, Signal::Kill).expect("SIGKILL");
}

#[test]
fn a_service_over_its_limit_is_left_down_and_the_rest_navigates() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("leavedown");
    let config = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.altimeter]\nmax_restarts = 2\nrestart_window_s = 60\ngive_up = \"leave-down\"\n",
    );
    let up = spawn_up_navigating(
        &ipc,
        &[
            "--config",
            config.path(),
            "--scenario",
            "static",
            "--duration",
            "120",
            "--json",
        ],
    );
    // Two kills are restarted; the third is one too many.
    let mut pid = running_pid(&ipc, "altimeter", None);
    for _ in 0..2 {
        sigkill(pid);
        pid = running_pid(&ipc, "altimeter", Some(pid));
    }
    sigkill(pid);
    let start = Instant::now();
    let report = loop {
        let r = ipc.status();
        if service(&r, "altimeter")["state"] == "given-up" {
            break r;
        }
        assert!(start.elapsed() < Duration::from_secs(10), "{r}");
        std::thread::sleep(Duration::from_millis(50));
    };
    assert_eq!(service(&report, "altimeter")["restarts"], 2, "{report}");
    for name in [
        "acquisition",
        "fusion",
        "navigator",
        "navigator-standby",
        "sim",
    ] {
        assert_eq!(
            service(&report, name)["state"],
            "running",
            "{name}: {report}"
        );
    }
    // Navigation goes on without the altimeter (its baro aiding goes stale).
    let more = ipc.run(&["echo", "nav", "--count", "100", "--timeout", "10"]);
    assert!(more.status.success(), "{}", stderr(&more));
    let summary = stop_up(&ipc, up);
    assert_eq!(summary["restarts"], 2, "{summary}");
}

#[test]
fn a_service_over_its_limit_stops_the_pipeline_when_so_configured() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("shutdown");
    let config = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.fusion]\nmax_restarts = 0\n",
    );
    let up = ipc
        .command()
        .args(["up", "--config", config.path(), "--scenario", "static"])
        .args(["--duration", "120"])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("cannot start rins up");
    let pid = running_pid(&ipc, "fusion", None);
    sigkill(pid);
    let out = up.wait_with_output().expect("rins up");
    assert!(!out.status.success(), "rins up should fail");
    let err = stderr(&out);
    assert!(
        err.contains("fusion exited (signal: 9 (SIGKILL)) 1 times within 60 s")
            && err.contains("stopping the pipeline"),
        "{err}"
    );
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}

#[test]
fn bad_restart_settings_are_refused_naming_the_key() {
    let unknown = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.gps]\nmax_restarts = 1\n",
    );
    fails_with(
        "limits-unknown",
        &["up", "--config", unknown.path()],
        &[
            "watchdog.services.gps: no such service",
            "navigator-standby",
        ],
    );
    let window = TempFile::new("limits", "toml", "[watchdog]\nrestart_window_s = -5\n");
    fails_with(
        "limits-window",
        &["up", "--config", window.path()],
        &["watchdog.restart_window_s = -5"],
    );
    let zero_window = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.navigator]\nrestart_window_s = 0\n",
    );
    fails_with(
        "limits-zero-window",
        &["up", "--config", zero_window.path()],
        &[
            "watchdog.services.navigator.restart_window_s = 0: must be a number of seconds in [0.001, 86400]",
        ],
    );
    let many = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.fusion]\nmax_restarts = 100000\n",
    );
    fails_with(
        "limits-many",
        &["up", "--config", many.path()],
        &["watchdog.services.fusion.max_restarts = 100000: must be <= 10000"],
    );
    let field = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.sim]\nmax_restart = 3\n",
    );
    fails_with(
        "limits-field",
        &["up", "--config", field.path()],
        &["max_restart", "max_restarts"],
    );
    let action = TempFile::new("limits", "toml", "[watchdog]\ngive_up = \"panic\"\n");
    fails_with(
        "limits-action",
        &["up", "--config", action.path()],
        &["give_up", "shutdown", "leave-down"],
    );
}

/// A service left down over its limit: the timed run reaches its end, its summary names the
/// service as failed, and `rins up` exits non-zero, saying which — the pipeline it was asked to run
/// was not whole.
#[test]
fn a_timed_run_with_a_service_given_up_ends_with_an_error() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("failedend");
    let config = TempFile::new(
        "limits",
        "toml",
        "[watchdog.services.altimeter]\nmax_restarts = 0\ngive_up = \"leave-down\"\n",
    );
    let up = spawn_up_navigating(
        &ipc,
        &[
            "--config",
            config.path(),
            "--scenario",
            "static",
            "--duration",
            "8",
            "--json",
        ],
    );
    sigkill(running_pid(&ipc, "altimeter", None));
    let out = up.wait_with_output().expect("rins up");
    let err = ipc.up_stderr();
    assert!(!out.status.success(), "rins up should fail:\n{err}");
    assert!(err.contains("altimeter given up during the run"), "{err}");
    let summary = common::last_json(&out);
    assert_eq!(summary["failed_services"], serde_json::json!(["altimeter"]));
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}
