//! Short `rins soak` runs: every fault is real — a SIGKILL or SIGSTOP to a service of a real
//! pipeline, a channel fault in the simulator, the serial device unplugged — and the pipeline must
//! come back from every one.

mod common;

use common::{Isolated, PipelineSlot, last_json};

fn soak(test: &str, args: &[&str]) -> (Isolated, serde_json::Value) {
    let ipc = Isolated::new(test);
    let out = ipc
        .command()
        .args(["soak", "--json"])
        .args(args)
        .output()
        .expect("cannot run rins soak");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = last_json(&out);
    assert_eq!(summary["shm_leaked"], 0, "{summary}");
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
    (ipc, summary)
}

#[test]
fn a_short_soak_restarts_every_killed_service_and_leaks_nothing() {
    let _slot = PipelineSlot::take();
    let args = [
        "--minutes",
        "0.25",
        "--min-interval",
        "2",
        "--max-interval",
        "3",
    ];
    let (_ipc, s) = soak("soak", &[&args[..], &["--faults", "kill"]].concat());
    // 15 s, the last 3.5 s without faults, a kill every 2–3 s: 3 to 5 kills (one may be put off
    // while a service is still restarting).
    let kills = s["kills"].as_u64().unwrap();
    assert!((2..=5).contains(&kills), "{s}");
    assert_eq!(s["faults"]["kill"]["count"], kills, "{s}");
    assert_eq!(s["restarts"].as_u64().unwrap(), kills, "{s}");
    assert_eq!(s["faults"]["kill"]["failed"], 0, "{s}");
    assert_eq!(s["faults"]["kill"]["unrecovered"], 0, "{s}");
    assert!(s["nav_samples"].as_u64().unwrap() > 5_000, "{s}");
}

#[test]
fn hangs_sensor_faults_and_unplugs_are_each_recovered_from() {
    let _slot = PipelineSlot::take();
    let (_ipc, s) = soak(
        "soakmix",
        &[
            "--minutes",
            "0.5",
            "--min-interval",
            "2",
            "--max-interval",
            "3",
            "--seed",
            "3",
            "--faults",
            "hang,sensor,disconnect",
        ],
    );
    let faults = &s["faults"];
    let count = |kind: &str| faults[kind]["count"].as_u64().unwrap();
    // 30 s, the last 7.5 s quiet, a fault every 2–3 s once the last one is recovered from (a hang
    // takes the 3 s heartbeat timeout and a restart).
    let total = count("hang") + count("sensor") + count("disconnect");
    assert!(total >= 3, "{s}");
    for kind in ["hang", "sensor", "disconnect"] {
        assert_eq!(faults[kind]["failed"], 0, "{kind}: {s}");
        assert_eq!(faults[kind]["unrecovered"], 0, "{kind}: {s}");
    }
    // Nothing was killed by the soak; every hung service was killed and restarted by the watchdog.
    assert_eq!(s["kills"], 0, "{s}");
    assert_eq!(s["restarts"].as_u64().unwrap(), count("hang"), "{s}");
    // A channel fault is isolated by fusion and costs no navigation output.
    assert_eq!(faults["sensor"]["lost_nav_samples"], 0, "{s}");
    assert_eq!(s["not_navigating_samples"], 0, "{s}");
}
