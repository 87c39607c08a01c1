//! `rins eval quadrotor` end to end through the binary. The recordings are not in the repository
//! (`quadrotor-4imu` in `$RINS_DATA_DIR`, else `<repo>/data`); the tests on them print a note and return when they
//! are absent. The error cases need no data.

mod common;

use std::process::{Command, Output};

use common::Scratch;
use serde_json::Value;

fn rins(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rins"))
        .args(args)
        .output()
        .unwrap()
}

fn assert_fails_naming(args: &[&str], needle: &str) {
    let out = rins(args);
    assert!(!out.status.success(), "rins {args:?} succeeded");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(needle), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

fn number(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("{v} is not a number"))
}

fn check_run(run: &Value) {
    for key in [
        "roll_pitch_rmse_deg",
        "height_error_m",
        "height_error_max_m",
    ] {
        assert!(number(&run[key]).is_finite(), "{key} in {run}");
    }
    assert!(number(&run["roll_pitch_rmse_deg"]) > 0.0, "{run}");
    assert!(run["rows"].as_u64().unwrap() > 50, "{run}");
}

#[test]
fn eval_quadrotor_reports_every_trial_every_unit_and_the_fused_units() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    let out = rins(&["eval", "quadrotor", dir.to_str().unwrap(), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    let trials = report["trials"].as_array().unwrap();
    assert_eq!(trials.len(), 12);
    for t in trials {
        assert!(t["name"].as_str().unwrap().contains("/path_"), "{t}");
        assert!(number(&t["duration_s"]) > 10.0, "{t}");
        let single = t["single"].as_array().unwrap();
        assert_eq!(single.len(), 4, "{t}");
        for (k, s) in single.iter().enumerate() {
            assert_eq!(s["imu"], k + 1);
            check_run(s);
        }
        check_run(&t["fused"]);
        assert!(t["fused"].get("imu").is_none(), "{t}");
    }
    let fused = number(&report["roll_pitch_rmse_deg"]);
    let median = number(&report["median_single_roll_pitch_rmse_deg"]);
    assert!(fused.is_finite() && median.is_finite());
    assert_eq!(
        report["fused_better_than_median_single"].as_bool().unwrap(),
        fused < median
    );
    assert_eq!(
        report["roll_pitch_target_met"].as_bool().unwrap(),
        fused <= 1.0
    );
}

#[test]
fn eval_quadrotor_prints_a_table_without_json() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    let out = rins(&["eval", "quadrotor", dir.to_str().unwrap()]);
    assert!(out.status.success());
    let table = String::from_utf8_lossy(&out.stdout);
    for needle in [
        "Horizontal/path_1",
        "StraightLine/path_4",
        "IMU_4",
        "fused",
        "median single",
    ] {
        assert!(table.contains(needle), "{needle} missing from\n{table}");
    }
}

#[test]
fn eval_quadrotor_names_a_missing_directory() {
    assert_fails_naming(
        &["eval", "quadrotor", "/nonexistent/quadrotor", "--json"],
        "/nonexistent/quadrotor",
    );
}

#[test]
fn eval_quadrotor_names_a_directory_without_trials() {
    let empty = Scratch::new("eval-quadrotor", "empty");
    let dir = empty.path().to_str().unwrap();
    assert_fails_naming(&["eval", "quadrotor", dir], dir);
}

#[test]
fn eval_quadrotor_names_a_bad_file() {
    let data = Scratch::new("eval-quadrotor", "bad");
    let trial = data.path().join("Horizontal/path_1");
    std::fs::create_dir_all(&trial).unwrap();
    std::fs::write(trial.join("IMU_1.csv"), "time,what\n1,2\n").unwrap();
    std::fs::write(trial.join("GT.csv"), "").unwrap();
    let file = trial.join("IMU_1.csv");
    assert_fails_naming(
        &["eval", "quadrotor", data.path().to_str().unwrap()],
        file.to_str().unwrap(),
    );
}

#[test]
fn eval_quadrotor_names_a_missing_truth_file() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    let data = Scratch::new("eval-quadrotor", "no-truth");
    let trial = data.path().join("Horizontal/path_1");
    std::fs::create_dir_all(&trial).unwrap();
    std::fs::copy(
        dir.join("Horizontal/path_1/IMU_1.csv"),
        trial.join("IMU_1.csv"),
    )
    .unwrap();
    assert_fails_naming(
        &["eval", "quadrotor", data.path().to_str().unwrap()],
        trial.join("GT.csv").to_str().unwrap(),
    );
}

#[test]
fn eval_quadrotor_names_a_bad_profile() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    assert_fails_naming(
        &[
            "eval",
            "quadrotor",
            dir.to_str().unwrap(),
            "--profile",
            "/nonexistent/uav.toml",
        ],
        "/nonexistent/uav.toml",
    );
}
