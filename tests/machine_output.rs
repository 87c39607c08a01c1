//! Output meant for programs: with `--json`, stdout is exactly one JSON document and everything
//! for a person (status lines, progress, logs) goes to stderr.

mod common;

use common::{Isolated, stderr};

#[test]
fn up_json_prints_one_json_document_and_the_status_lines_on_stderr() {
    let ipc = Isolated::new("upjson");
    let out = ipc.run(&["up", "--scenario", "static", "--duration", "3", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    // The whole of stdout, not its last line: one document and nothing else.
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "stdout is not one JSON document ({e}):\n{}",
            String::from_utf8_lossy(&out.stdout)
        )
    });
    assert!(
        summary["frames"].as_u64().is_some_and(|n| n > 0),
        "{summary}"
    );
    // CPU time and peak memory of every process, from /proc: each service ran once, used some
    // memory (a Rust process with iceoryx2 is megabytes), and no more than the whole machine.
    let processes = summary["processes"].as_array().expect("processes");
    for name in [
        "acquisition",
        "fusion",
        "navigator",
        "navigator-standby",
        "altimeter",
        "sim",
        "watchdog",
    ] {
        let p = processes
            .iter()
            .find(|p| p["name"] == name)
            .unwrap_or_else(|| panic!("no {name} in {summary}"));
        assert_eq!(p["incarnations"].as_u64(), Some(1), "{summary}");
        assert!(
            p["peak_rss_kib"].as_u64().is_some_and(|k| k > 1024),
            "{summary}"
        );
        assert!(p["cpu_s"].as_f64().is_some_and(|c| c >= 0.0), "{summary}");
    }
    // The standby lane reads its input in batches of 20 samples while the primary serves: a
    // twentieth of the primary's wake-ups, under half of them even with a second of serving
    // sample by sample (the primary lagging once on a loaded machine).
    let wakeups = |name: &str| {
        processes.iter().find(|p| p["name"] == name).unwrap()["wakeups"]
            .as_u64()
            .unwrap()
    };
    assert!(
        2 * wakeups("navigator-standby") < wakeups("navigator"),
        "{summary}"
    );
    let cores = std::thread::available_parallelism().map_or(1, usize::from) as f64;
    let pipeline = summary["pipeline_cpu_pct"]
        .as_f64()
        .expect("pipeline_cpu_pct");
    assert!(
        pipeline > 0.0 && pipeline <= 100.0 * cores + 5.0,
        "{summary}"
    );
    // The once-a-second status lines are still there, on stderr.
    let err = stderr(&out);
    assert!(
        err.lines()
            .any(|l| l.starts_with("t=") && l.contains(" imu ")),
        "no status line on stderr:\n{err}"
    );
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}
