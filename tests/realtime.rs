//! `rins up --realtime`: every service asks for its `[realtime]` settings; what the system grants
//! is in force (SCHED_FIFO at the configured priority), what it refuses is logged once by the
//! service that asked, and the pipeline navigates either way.

mod common;

use common::{Isolated, PipelineSlot, TempFile, last_json, stop_up_output};

/// (policy, real-time priority) of process `pid`: fields 41 and 40 of `/proc/PID/stat`.
fn scheduling(pid: u64) -> (u32, u32) {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).expect("/proc/PID/stat");
    let fields: Vec<&str> = stat[stat.rfind(')').unwrap() + 2..]
        .split_ascii_whitespace()
        .collect();
    // Fields after the name start at 3.
    (
        fields[41 - 3].parse().unwrap(),
        fields[40 - 3].parse().unwrap(),
    )
}

#[test]
fn granted_settings_are_in_force_and_refused_ones_are_logged_once() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("realtime");
    // A CPU no machine here has: the system refuses acquisition's affinity.
    let text = rins::config::BUILT_IN.replace("# acquisition = [1]", "acquisition = [1023]");
    assert_ne!(text, rins::config::BUILT_IN);
    let config = TempFile::new("realtime", "toml", &text);
    let up = ipc
        .command()
        .args(["up", "--scenario", "static", "--duration", "300", "--json"])
        .args(["--realtime", "--config", config.path()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("rins up");
    let first = ipc.run(&["echo", "nav", "--count", "1", "--timeout", "120"]);
    assert!(first.status.success(), "no navigation: {first:?}");
    let status = last_json(&ipc.run(&["status", "--json", "--timeout", "30"]));
    let pid_of = |service: &str| {
        status["services"]
            .as_array()
            .unwrap()
            .iter()
            .find(|s| s["service"] == service)
            .and_then(|s| s["pid"].as_u64())
            .unwrap_or_else(|| panic!("{service} in {status}"))
    };
    let fusion = scheduling(pid_of("fusion"));
    let navigator = scheduling(pid_of("navigator"));
    let out = stop_up_output(&ipc, up);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let summary = last_json(&out);
    assert_eq!(summary["dropped"], 0, "{summary}");
    assert!(summary["nav_samples"].as_u64().unwrap() > 0, "{summary}");

    let refusals: Vec<&str> = stderr
        .lines()
        .filter(|l| l.contains("real-time setting refused"))
        .collect();
    let affinity: Vec<&&str> = refusals
        .iter()
        .filter(|l| l.contains("setting=\"cpus\""))
        .collect();
    assert_eq!(affinity.len(), 1, "{refusals:#?}");
    assert!(
        affinity[0].contains("service=\"acquisition\"") && affinity[0].contains("[1023]"),
        "{}",
        affinity[0]
    );
    // SCHED_FIFO (1) at the configured priority, or the system's refusal in the log.
    for (service, (policy, priority), configured) in
        [("fusion", fusion, 79), ("navigator", navigator, 78)]
    {
        let refused = refusals.iter().any(|l| {
            l.contains(&format!("service=\"{service}\"")) && l.contains("setting=\"priority\"")
        });
        if refused {
            assert_eq!(
                policy, 0,
                "{service} refused FIFO but runs under policy {policy}"
            );
        } else {
            assert_eq!((policy, priority), (1, configured), "{service}");
        }
    }
}
