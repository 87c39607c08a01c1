//! A Python program reads a live topic: `examples/python/echo_nav.py` (iceoryx2's Python binding and
//! the `ctypes` mirror in `python/rins_topics.py`) joins a running pipeline through the iceoryx2
//! configuration file `rins up` writes, and receives the navigation stream: the payload version,
//! unit quaternions and strictly increasing sequence numbers; the configuration file is there while
//! the pipeline runs and gone after it stops, with nothing left in shared memory.

mod common;

use common::python::{interpreter, run_script};
use common::{Isolated, PipelineSlot, spawn_up_navigating, stop_up};

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
