//! `rins eval fdi` on the real quadrotor recordings and `rins mc`, end to end through the binary.
//! The recordings are not in the repository (`quadrotor-4imu` in `$RINS_DATA_DIR`, else
//! `<repo>/data`); the FDI tests print a note and return when they are absent.

mod common;

use std::process::Command;

use serde_json::Value;

fn rins() -> Command {
    Command::new(env!("CARGO_BIN_EXE_rins"))
}

fn run_json(args: &[&str]) -> Value {
    let out = rins().args(args).output().unwrap();
    assert!(
        out.status.success(),
        "rins {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn eval_fdi() -> Option<Value> {
    let dir = common::quadrotor_data_dir()?;
    Some(run_json(&["eval", "fdi", dir.to_str().unwrap(), "--json"]))
}

fn breakdown<'a>(report: &'a Value, config: &str, fault: &str) -> Vec<&'a Value> {
    report["breakdown"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|b| b["configuration"] == config && b["fault"] == fault)
        .collect()
}

#[test]
fn eval_fdi_reports_every_trial_and_isolates_health_faults_on_the_pyramid() {
    let Some(report) = eval_fdi() else { return };
    for key in [
        "trials",
        "false_alarms",
        "faults_injected",
        "detected",
        "isolated",
        "correctly_isolated",
        "detection_delay_ms_p50",
        "detection_delay_ms_max",
        "isolation_delay_ms_p50",
        "isolation_delay_ms_max",
        "configurations",
        "per_trial",
    ] {
        assert!(report.get(key).is_some(), "missing {key}");
    }
    assert_eq!(report["trials"], 12);
    assert_eq!(report["flights_total"], 12);
    assert_eq!(report["flights_evaluated"], 12);
    // 356 s of recording over the twelve flights (the units' common spans).
    let hours = report["flight_hours"].as_f64().unwrap();
    assert!((hours - 0.0989).abs() < 0.0005, "{hours}");
    // Two configurations per trial.
    assert_eq!(report["per_trial"].as_array().unwrap().len(), 24);
    // 12 trials × 2 types × (4 + 12 channels) × 5 fault kinds.
    assert_eq!(report["faults_injected"], 12 * 2 * 16 * 5);
    // Channel-health faults on four single-axis channels: each is isolated, and on the right
    // channel (dead on the first faulty sample, saturation after the 5-sample run of counts at the
    // rail, stuck after 20 identical counts at most).
    for (fault, max_samples) in [("dead", 1), ("saturated", 5), ("stuck", 20)] {
        for b in breakdown(&report, "pyramid4", fault) {
            assert_eq!(b["correctly_isolated"], b["faults_injected"], "{b}");
            let max = b["isolation_delay_samples_max"].as_u64().unwrap();
            assert!(max <= max_samples, "{fault}: {max} samples");
        }
    }
}

#[test]
fn eval_fdi_names_a_missing_directory() {
    let out = rins()
        .args(["eval", "fdi", "/nonexistent/quadrotor", "--json"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/quadrotor"), "{err}");
}

#[test]
fn mc_short_runs_navigate_through_the_kill_on_the_redundant_block_only() {
    let report = run_json(&["mc", "--runs", "2", "--duration", "60", "--json"]);
    assert_eq!(report["runs"], 2);
    assert_eq!(report["duration_s"], 60.0);
    // Without --kill-at a short flight is killed in its middle.
    assert_eq!(report["kill_at_s"], 30.0);
    assert_eq!(report["records"].as_array().unwrap().len(), 2);
    let r = &report["redundant"]["kill"];
    let o = &report["orthogonal"]["kill"];
    // The redundant block keeps a solution on every tick after the kill; the triad loses it from
    // the kill to the end (30 s, to the tick) in both runs.
    assert_eq!(r["lost_runs"], 0);
    assert_eq!(r["faulted"]["unsolved_s"]["max"], 0.0);
    assert_eq!(o["lost_runs"], 2);
    let lost = o["faulted"]["unsolved_s"]["mean"].as_f64().unwrap();
    assert!((lost - 30.0).abs() < 0.01, "{lost}");
}
