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

/// Three flights (57 s) of the twelve: enough for leave-one-flight-out, short enough for a debug
/// build.
const SUBSET: [&str; 3] = [
    "Horizontal/path_1",
    "Horizontal/path_6",
    "StraightLine/path_3",
];

fn eval_fdi_subset() -> Option<Value> {
    let dir = common::quadrotor_data_dir()?;
    let mut args = vec!["eval", "fdi", dir.to_str().unwrap(), "--json"];
    for t in SUBSET {
        args.extend(["--trial", t]);
    }
    Some(run_json(&args))
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
fn eval_fdi_reports_cross_validated_figures_and_isolates_health_faults_on_the_pyramid() {
    let Some(report) = eval_fdi_subset() else {
        return;
    };
    for key in [
        "trials",
        "false_alarms",
        "cv_false_alarms",
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
        "roc",
        "operating_points",
        "repairs",
    ] {
        assert!(report.get(key).is_some(), "missing {key}");
    }
    assert_eq!(report["trials"], 3);
    assert_eq!(report["flights_total"], 3);
    assert_eq!(report["flights_evaluated"], 3);
    // 57.0 s of recording over the three flights (the units' common spans).
    let hours = report["flight_hours"].as_f64().unwrap();
    assert!((hours - 57.0 / 3600.0).abs() < 0.0003, "{hours}");
    // The headline false alarms are the cross-validated ones, per configuration too.
    assert_eq!(report["false_alarms"], report["cv_false_alarms"]);
    for c in report["configurations"].as_array().unwrap() {
        assert_eq!(c["false_alarms"], c["cv_false_alarms"], "{c}");
        assert_eq!(c["flights"], 3, "{c}");
    }
    // Two configurations per flight, each scored with a setting of the grid.
    let rows = report["per_trial"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    for r in rows {
        let p = r["setting"]["false_alarm_probability"].as_f64().unwrap();
        assert!((1e-15..=1e-5).contains(&p), "{r}");
        // The installation and arms came from the two other flights.
        assert_eq!(r["geometry_flights_pooled"], 2, "{r}");
    }
    // 3 flights × 2 types × (4 + 12 channels) × 8 fault kinds.
    assert_eq!(report["faults_injected"], 3 * 2 * 16 * 8);
    // The ROC: five swept probabilities per configuration, each with every fault kind.
    let roc = report["roc"].as_array().unwrap();
    assert_eq!(roc.len(), 2 * 5);
    for p in roc {
        assert_eq!(p["detection"].as_array().unwrap().len(), 8, "{p}");
        let per_hour = p["false_alarms_per_hour"].as_f64().unwrap();
        let fa = p["false_alarms"].as_f64().unwrap();
        assert!(
            (per_hour - fa / hours).abs() < 1e-6 * (1.0 + per_hour),
            "{p}"
        );
    }
    assert_eq!(report["operating_points"].as_array().unwrap().len(), 2);
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

/// A data set in which some flights lost units, one has a single unit and one cannot be read:
/// each flight is evaluated with what it has, nothing aborts the evaluation.
#[test]
fn eval_fdi_evaluates_flights_with_fewer_units_and_lists_what_it_cannot_use() {
    let Some(data) = common::quadrotor_data_dir() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("rins-fdi-units-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let link = |from: &str, to: &str, units: &[usize]| {
        let target = dir.join("Mixed").join(to);
        std::fs::create_dir_all(&target).unwrap();
        std::os::unix::fs::symlink(data.join(from).join("GT.csv"), target.join("GT.csv")).unwrap();
        for u in units {
            let name = format!("IMU_{u}.csv");
            std::os::unix::fs::symlink(data.join(from).join(&name), target.join(&name)).unwrap();
        }
    };
    link("Horizontal/path_1", "path_1", &[1, 2, 4]);
    link("Horizontal/path_6", "path_2", &[1, 2, 4]);
    link("StraightLine/path_3", "path_3", &[1]);
    // A flight whose every unit file is garbage.
    let bad = dir.join("Mixed/path_4");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::copy(data.join("Horizontal/path_1/GT.csv"), bad.join("GT.csv")).unwrap();
    std::fs::write(bad.join("IMU_1.csv"), "not,a,recording\n1,2\n").unwrap();
    let report = run_json(&["eval", "fdi", dir.to_str().unwrap(), "--json"]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(report["flights_total"], 4);
    assert_eq!(report["flights_evaluated"], 2);
    // Three units: the stacked nine rows, no pyramid.
    let configs = report["configurations"].as_array().unwrap();
    assert_eq!(configs.len(), 1, "{configs:?}");
    assert_eq!(configs[0]["configuration"], "stacked9");
    assert_eq!(configs[0]["channels"], 9);
    // One unit: listed, not an error; the unreadable flight: listed with its reason.
    let single = report["single_unit"].as_array().unwrap();
    assert_eq!(single.len(), 1);
    assert_eq!(single[0]["trial"], "Mixed/path_3");
    let skipped = report["skipped"].as_array().unwrap();
    assert_eq!(skipped.len(), 1, "{skipped:?}");
    assert_eq!(skipped[0]["trial"], "Mixed/path_4");
    assert_eq!(report["repairs"]["trials_failed"], 1);
    // 2 flights × 2 types × 9 channels × 8 kinds, dead channels found at once.
    assert_eq!(report["faults_injected"], 2 * 2 * 9 * 8);
    for b in breakdown(&report, "stacked9", "dead") {
        assert_eq!(b["detected"], b["faults_injected"], "{b}");
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
