//! A Python program reads a live topic: `examples/python/echo_nav.py` (iceoryx2's Python binding and
//! the `ctypes` mirror in `python/rins_topics.py`) joins a running pipeline through the iceoryx2
//! configuration file `rins up` writes, and receives the navigation stream: the payload version,
//! unit quaternions and strictly increasing sequence numbers; the configuration file is there while
//! the pipeline runs and gone after it stops, with nothing left in shared memory.
//!
//! Python follows the navigator lanes as Rust consumers do: `python/lane_selector.py` passes the
//! cases of the Rust selector's rule with the Rust defaults, and `rins_topics.subscribe_nav` loses
//! no sequence number when the selected navigator lane is killed, switching to the other. The
//! program in `python/README.md` runs as printed and prints what it received.
//!
//! These tests need the interpreter of `python/setup-venv` in `RINS_PYTHON` (read when the tests
//! are built): without it they are ignored.

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{Receiver, channel};
use std::time::{Duration, Instant};

use common::python::{interpreter, run_script};
use common::{Isolated, PipelineSlot, TempFile, spawn_up_navigating, stop_up};
use ipc_types::{NavMode, Stage};
use rins_navigator::lanes::{LANES, PENDING, SelectorConfig};
use rins_test_support::signal::{Signal, send_signal};
use serde_json::{Value, json};

const SAMPLES: usize = 200;

/// Runs the Rust example `consume_nav` (20 samples) on the pipeline when it was built (`cargo test`
/// builds the examples; `cargo test --test python_topics` alone does not).
fn consume_nav(ipc: &Isolated) -> Option<std::process::Output> {
    let exe = std::env::current_exe().ok()?;
    let example = exe.parent()?.parent()?.join("examples/consume_nav");
    if !example.is_file() {
        eprintln!("consume_nav not built: the Rust example is not run");
        return None;
    }
    let out = std::process::Command::new(example)
        .arg("20")
        .env("RINS_IPC_PREFIX", &ipc.prefix)
        .env("RINS_IPC_ROOT", &ipc.root)
        .env("RINS_LOG", "warn")
        .output()
        .expect("cannot run consume_nav");
    Some(out)
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn python_receives_the_navigation_stream_of_a_running_pipeline() {
    let Some(python) = interpreter("python_receives_the_navigation_stream_of_a_running_pipeline")
    else {
        return;
    };
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("pytopics");
    let config_file = ipc
        .root
        .join(format!("{}run", ipc.prefix))
        .join("iceoryx2.toml");

    // No deployment yet: a clear refusal, not a hang.
    let out = run_script(
        &python,
        &ipc,
        "examples/python/echo_nav.py",
        &["--count", "1"],
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("no rins deployment") && stderr.contains("iceoryx2.toml"),
        "{stderr}"
    );

    let up = spawn_up_navigating(&ipc, &["--scenario", "static", "--json"]);
    assert!(config_file.is_file(), "{} missing", config_file.display());
    let count = SAMPLES.to_string();
    let out = run_script(
        &python,
        &ipc,
        "examples/python/echo_nav.py",
        &["--count", &count, "--json", "--timeout", "30"],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let rust = consume_nav(&ipc);
    let summary = stop_up(&ipc, up);
    if let Some(rust) = rust {
        let text = String::from_utf8_lossy(&rust.stdout);
        assert!(rust.status.success(), "consume_nav: {rust:?}");
        assert_eq!(
            text.lines().filter(|l| l.starts_with("seq ")).count(),
            20,
            "{text}"
        );
    }
    assert!(out.status.success(), "echo_nav.py failed:\n{stderr}");
    eprintln!("{}", stderr.trim());

    let samples: Vec<serde_json::Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{l:?}: {e}")))
        .collect();
    assert!(samples.len() >= SAMPLES, "{} samples", samples.len());
    let mut last_seq = None;
    for s in &samples {
        assert_eq!(
            s["version"].as_u64(),
            Some(u64::from(ipc_types::PAYLOAD_VERSION)),
            "{s}"
        );
        let q: Vec<f64> = s["quaternion"]
            .as_array()
            .expect("quaternion")
            .iter()
            .map(|v| v.as_f64().expect("a number"))
            .collect();
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!((norm - 1.0).abs() < 1e-6, "|q| = {norm}: {s}");
        let seq = s["seq"].as_u64().expect("seq");
        if let Some(last) = last_seq {
            assert!(seq > last, "seq {seq} after {last}");
        }
        last_seq = Some(seq);
    }
    assert!(!config_file.exists(), "{} left", config_file.display());
    assert_eq!(summary["shm_leaked"].as_u64(), Some(0), "{summary}");
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn the_python_lane_selector_follows_the_rust_rule_with_the_rust_defaults() {
    let Some(python) = interpreter("the_python_lane_selector_follows_the_rust_rule") else {
        return;
    };
    let config = SelectorConfig::default();
    let usable: Vec<u8> = (0..=u8::MAX)
        .filter(|&m| NavMode::from_u8(m).is_some_and(NavMode::is_usable))
        .collect();
    let rust = json!({
        "switch_lag": config.switch_lag,
        "dead_after_ns": config.dead_after_ns,
        "dead_after_untrusted_ns": config.dead_after_untrusted_ns,
        "settle": config.settle,
        "min_dwell": config.min_dwell,
        "pending": PENDING,
        "lanes": LANES,
        "navigator_stage": Stage::Navigator as usize,
        "usable_modes": usable,
    });
    let ipc = Isolated::new("pyselector");
    let out = run_script(
        &python,
        &ipc,
        "python/tests/check_lane_selector.py",
        &[&rust.to_string()],
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "check_lane_selector.py failed:\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Every case, and the defaults compared with Rust's.
    assert!(stdout.trim().ends_with("cases pass"), "{stdout}");
}

/// The process of each navigator lane.
const LANE_SERVICES: [&str; LANES] = ["navigator", "navigator-standby"];

fn pid_of(ipc: &Isolated, name: &str) -> u64 {
    let report = ipc.status();
    report["services"]
        .as_array()
        .expect("services")
        .iter()
        .find(|s| s["service"] == name && s["state"] == "running")
        .and_then(|s| s["pid"].as_u64())
        .unwrap_or_else(|| panic!("{name} not running: {report}"))
}

/// `python/tests/follow_nav.py` on the pipeline, its JSON lines on a channel; it stops when its
/// standard input closes.
fn follow_nav(python: &Path, ipc: &Isolated) -> (Child, Receiver<Value>) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("python/tests/follow_nav.py");
    let mut child = Command::new(python)
        .arg(script)
        .env("RINS_IPC_PREFIX", &ipc.prefix)
        .env("RINS_IPC_ROOT", &ipc.root)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("cannot run follow_nav.py");
    let stdout = child.stdout.take().expect("follow_nav stdout");
    let (tx, rx) = channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let v: Value = serde_json::from_str(&line)
                .unwrap_or_else(|e| panic!("follow_nav printed {line:?}: {e}"));
            if tx.send(v).is_err() {
                break;
            }
        }
    });
    (child, rx)
}

/// The sample lines that arrive within `span`.
fn samples_for(rx: &Receiver<Value>, span: Duration) -> Vec<Value> {
    let end = Instant::now() + span;
    let mut got = Vec::new();
    while Instant::now() < end {
        let v = rx
            .recv_timeout(Duration::from_secs(5))
            .expect("the Python consumer's stream stopped");
        got.push(v);
    }
    got
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn python_loses_no_sample_when_the_selected_navigator_lane_is_killed() {
    let Some(python) = interpreter("python_loses_no_sample_when_the_selected_lane_is_killed")
    else {
        return;
    };
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("pylanes");
    let up = spawn_up_navigating(
        &ipc,
        &["--scenario", "static", "--duration", "120", "--json"],
    );
    let (mut consumer, rx) = follow_nav(&python, &ipc);
    // Both lanes aligned and settled (the selector trusts a solution 2 s after alignment): a
    // second of trusted samples, so that the other lane takes over after the 8 ms dead time, not
    // the 100 ms of a lane not trusted yet.
    let mut before = Vec::new();
    let mut trusted_run = 0;
    let limit = Instant::now() + Duration::from_secs(90);
    while trusted_run < 1000 {
        assert!(Instant::now() < limit, "no trusted solution in 90 s");
        let s = rx
            .recv_timeout(Duration::from_secs(60))
            .expect("no navigation sample in Python");
        trusted_run = if s["trusted"] == true {
            trusted_run + 1
        } else {
            0
        };
        before.push(s);
    }
    let selected = before
        .last()
        .and_then(|s| s["selected"].as_u64())
        .expect("selected") as usize;
    let victim = pid_of(&ipc, LANE_SERVICES[selected]);
    // A process of this test's own pipeline.
    send_signal(victim, Signal::Kill).expect("SIGKILL");
    let after = samples_for(&rx, Duration::from_secs(4));
    // Standard input closed: the consumer prints its summary and ends.
    drop(consumer.stdin.take());
    let mut rest: Vec<Value> = rx.iter().collect();
    let status = consumer.wait().expect("follow_nav.py did not finish");
    let summary = rest.pop().expect("no summary")["summary"].clone();
    let stopped = stop_up(&ipc, up);
    assert!(status.success(), "follow_nav.py: {status:?}");
    eprintln!(
        "killed {} (lane {selected}): {summary}",
        LANE_SERVICES[selected]
    );

    let all: Vec<&Value> = before.iter().chain(&after).chain(&rest).collect();
    let seqs: Vec<u64> = all
        .iter()
        .map(|s| s["seq"].as_u64().expect("seq"))
        .collect();
    assert!(seqs.windows(2).all(|p| p[1] > p[0]), "not in order");
    assert_eq!(
        summary["received"].as_u64(),
        Some(seqs.len() as u64),
        "{summary}"
    );
    // Every sequence number a lane delivered is in the output. What neither lane had (a frame
    // the loaded machine's input lost) cannot be, and is counted apart.
    assert_eq!(summary["lost"], json!([]), "{summary}");
    let holes = summary["holes"].as_array().map_or(0, Vec::len) as u64;
    assert_eq!(summary["missing"].as_u64(), Some(holes), "{summary}");
    assert_eq!(summary["skipped"].as_u64(), Some(holes), "{summary}");
    // The killed lane was the one delivering: the other lane took over at the next sequence
    // number, as soon as the selected lane was silent for the dead time.
    let other = (1 - selected) as u64;
    let at = after
        .iter()
        .position(|s| s["selected"].as_u64() == Some(other))
        .unwrap_or_else(|| panic!("never switched to lane {other}: {summary}"));
    let previous = if at == 0 {
        before.last()
    } else {
        after.get(at - 1)
    };
    let previous = previous.and_then(|s| s["seq"].as_u64()).expect("seq");
    assert_eq!(after[at]["seq"].as_u64(), Some(previous + 1), "{summary}");
    assert_eq!(after[at]["lane"].as_u64(), Some(other), "{summary}");
    // Four seconds of the 1 kHz stream after the kill, at least (a loaded machine delivers late,
    // never less).
    assert!(
        after.len() >= 3000,
        "{} samples after the kill",
        after.len()
    );
    assert_eq!(stopped["shm_leaked"].as_u64(), Some(0), "{stopped}");
}

/// The program under "In a program of your own" in python/README.md: its indented code blocks,
/// in order, as one script.
fn readme_program() -> String {
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("python/README.md"))
            .expect("cannot read python/README.md");
    let section = readme
        .split("\n## ")
        .find(|s| s.starts_with("In a program of your own"))
        .expect("python/README.md has no section \"In a program of your own\"");
    let mut program = String::new();
    for line in section.lines() {
        if let Some(code) = line.strip_prefix("    ") {
            program.push_str(code);
            program.push('\n');
        } else if line.trim().is_empty() && !program.is_empty() {
            program.push('\n');
        }
    }
    program
}

#[test]
fn the_readme_shows_a_program_that_follows_the_navigation_lanes() {
    let program = readme_program();
    for needed in [
        "import rins_topics as rt",
        "rt.open_node(",
        "rt.subscribe_nav(",
        "print(",
    ] {
        assert!(program.contains(needed), "no {needed:?} in:\n{program}");
    }
}

#[test]
#[cfg_attr(not(rins_python), ignore = "needs RINS_PYTHON: python/setup-venv")]
fn the_readme_program_receives_samples_as_printed() {
    let Some(python) = interpreter("the_readme_program_receives_samples_as_printed") else {
        return;
    };
    let program = readme_program();
    let script = TempFile::new("pyreadme", "py", &program);
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("pyreadme");
    let up = spawn_up_navigating(&ipc, &["--scenario", "static", "--json"]);
    // As a reader runs it: from the repository root.
    let child = Command::new(&python)
        .arg(script.path())
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .env("RINS_IPC_PREFIX", &ipc.prefix)
        .env("RINS_IPC_ROOT", &ipc.root)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot run python");
    let out = child.wait_with_output().expect("the README program");
    let summary = stop_up(&ipc, up);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "the README program failed:\n{program}\n{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{}", stdout.trim());
    // Ten navigation samples, one line each: sequence number, mode, lane; consecutive.
    let nav: Vec<u64> = stdout
        .lines()
        .filter(|l| l.contains(" lane "))
        .map(|l| {
            l.split_whitespace()
                .next()
                .and_then(|seq| seq.parse().ok())
                .unwrap_or_else(|| panic!("{l:?}"))
        })
        .collect();
    assert_eq!(nav.len(), 10, "{stdout}");
    assert!(nav.windows(2).all(|p| p[1] == p[0] + 1), "{nav:?}");
    // And one fused IMU sample.
    assert!(
        stdout.lines().any(|l| l.starts_with("fused imu ")),
        "{stdout}"
    );
    assert_eq!(summary["shm_leaked"].as_u64(), Some(0), "{summary}");
}
