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
    // The AHRS mode, with no flight it can use, fails the same way.
    assert_fails_naming(
        &[
            "eval",
            "quadrotor",
            data.path().to_str().unwrap(),
            "--mode",
            "ahrs",
        ],
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

/// `rins eval quadrotor DIR --mode MODE --json` and any `extra` arguments, which must succeed.
fn report(dir: &std::path::Path, mode: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "eval",
        "quadrotor",
        dir.to_str().unwrap(),
        "--mode",
        mode,
        "--json",
    ];
    args.extend_from_slice(extra);
    let out = rins(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn ahrs_report(dir: &std::path::Path) -> Value {
    report(dir, "ahrs", &[])
}

fn per_unit(report: &Value, key: &str) -> Vec<f64> {
    report[key].as_array().unwrap().iter().map(number).collect()
}

/// The AHRS mode on the twelve flights: every flight evaluated, the data's three repeated
/// timestamps and one missing sample repaired, each unit alone and each unit's own filter scored,
/// and the fused solution below every one of the units' own filters (the claim docs/accuracy.md makes).
#[test]
fn eval_quadrotor_ahrs_scores_every_flight_beside_each_units_own_filter() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    let r = ahrs_report(&dir);
    assert_eq!(r["flights_total"], 12, "{r}");
    assert_eq!(r["flights_evaluated"], 12, "{r}");
    assert_eq!(r["repairs"]["repeated_timestamps"], 3, "{r}");
    assert_eq!(r["repairs"]["missing_samples_filled"], 1, "{r}");
    assert_eq!(r["repairs"]["trials_failed"], 0, "{r}");
    let fused = number(&r["roll_pitch_rmse_deg"]);
    let peer = per_unit(&r, "peer_roll_pitch_rmse_deg");
    let single = per_unit(&r, "single_roll_pitch_rmse_deg");
    assert_eq!((peer.len(), single.len()), (4, 4), "{r}");
    // The units' own filters are good to 0.5–1.5° against the reference on these flights.
    for p in &peer {
        assert!((0.3..1.5).contains(p), "{peer:?}");
    }
    assert!(fused > 0.2 && fused < peer.iter().copied().fold(f64::INFINITY, f64::min));
    assert_eq!(r["fused_better_than_every_peer"], true);
    for f in r["flights"].as_array().unwrap() {
        assert!(f["rows"].as_u64().unwrap() > 100, "{f}");
        assert!(
            f["candidate"].as_str().unwrap().contains("bias prior"),
            "{f}"
        );
        assert_eq!(f["file_offsets_s"].as_array().unwrap().len(), 4, "{f}");
    }
    check_references(&r, fused);
}

/// The reference filters and the average of the units' own filters, scored the same way: each
/// grid's choice made on every flight, the default settings named, every figure finite and above
/// rins's fused one (Madgwick 2.9°, Mahony 1.35° cross-validated on these flights; the averaged
/// own filters 0.8°), and the start windows' means over the flights that reach them.
fn check_references(r: &Value, fused: f64) {
    for (filter, settings, default) in [
        ("madgwick", 4, "Madgwick beta 0.1"),
        ("mahony", 12, "Mahony kp 0.5 ki 0"),
    ] {
        let grid = r[filter]["grid"].as_array().unwrap();
        assert_eq!(grid.len(), settings, "{filter}");
        let chosen: u64 = grid.iter().map(|c| c["chosen"].as_u64().unwrap()).sum();
        assert_eq!(chosen, 12, "{filter}");
        assert_eq!(r[filter]["default"]["setting"], default);
        for setting in ["default", "cross_validated"] {
            let s = &r[filter][setting];
            let figure = number(&s["fused_roll_pitch_rmse_deg"]);
            assert!(figure > fused && figure < 5.0, "{filter} {setting}: {s}");
            for unit in s["single_roll_pitch_rmse_deg"].as_array().unwrap() {
                assert!(number(unit) > 0.2 && number(unit) < 8.0, "{filter}: {s}");
            }
            assert_eq!(s["samples_without_force"], 0, "{s}");
        }
    }
    let average = number(&r["peer_average_roll_pitch_rmse_deg"]);
    assert!(average > fused && average < 1.5, "{average}");
    assert_eq!(r["window_starts_s"], serde_json::json!([5.0, 10.0, 30.0]));
    // The straight-line flights end before 30 s.
    assert_eq!(r["flights_per_window"], serde_json::json!([12, 12, 6]));
    assert_eq!(r["long_flight_windows"]["flights"], 6);
    for key in ["fused_window_rmse_deg", "peer_average_window_rmse_deg"] {
        for w in r[key].as_array().unwrap() {
            assert!(number(w) > 0.1 && number(w) < 2.0, "{key}: {r}");
        }
    }
}

/// Failed units, a counter wrap, an unreadable unit file and an empty reference file: the flights
/// are evaluated with what they have, the broken one is left out with its reason, and the repairs
/// are counted; nothing aborts.
#[test]
fn eval_quadrotor_ahrs_goes_on_past_failed_units_and_broken_files() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    let scratch = Scratch::new("quadrotor-broken", "data");
    let root = scratch.path();
    for group in ["Horizontal", "StraightLine"] {
        for entry in std::fs::read_dir(dir.join(group)).unwrap() {
            let from = entry.unwrap().path();
            let to = root.join(group).join(from.file_name().unwrap());
            std::fs::create_dir_all(&to).unwrap();
            for file in std::fs::read_dir(&from).unwrap() {
                let file = file.unwrap().path();
                std::fs::copy(&file, to.join(file.file_name().unwrap())).unwrap();
            }
        }
    }
    for k in 2..=4 {
        std::fs::remove_file(root.join(format!("Horizontal/path_2/IMU_{k}.csv"))).unwrap();
    }
    // The unit's 32-bit microsecond counter wraps after row 2000.
    let wrapped = root.join("Horizontal/path_3/IMU_1.csv");
    let text = std::fs::read_to_string(&wrapped).unwrap();
    let lines: Vec<String> = text
        .lines()
        .enumerate()
        .map(|(i, line)| {
            if i <= 2001 {
                return line.to_string();
            }
            let (t, rest) = line.split_once(',').unwrap();
            format!("{},{rest}", t.parse::<f64>().unwrap() - 4294.967296)
        })
        .collect();
    std::fs::write(&wrapped, lines.join("\n") + "\n").unwrap();
    std::fs::write(root.join("Horizontal/path_7/IMU_3.csv"), "garbage\n1,2,3\n").unwrap();
    std::fs::write(root.join("StraightLine/path_2/GT.csv"), "").unwrap();

    let r = ahrs_report(root);
    assert_eq!(r["flights_total"], 12, "{r}");
    assert_eq!(r["flights_evaluated"], 11, "{r}");
    assert_eq!(r["repairs"]["counter_wraps"], 1, "{r}");
    assert_eq!(r["repairs"]["imu_files_skipped"], 1, "{r}");
    assert_eq!(r["repairs"]["trials_failed"], 1, "{r}");
    let failures = r["failures"].as_array().unwrap();
    assert_eq!(failures.len(), 1, "{r}");
    assert_eq!(failures[0]["trial"], "StraightLine/path_2");
    assert!(failures[0]["reason"].as_str().unwrap().contains("GT.csv"));
    let flights = r["flights"].as_array().unwrap();
    let one_unit = flights
        .iter()
        .find(|f| f["name"] == "Horizontal/path_2")
        .unwrap();
    assert_eq!(one_unit["imus"], serde_json::json!([1]));
    assert!(
        number(&one_unit["fused_roll_pitch_rmse_deg"]) < 2.0,
        "{one_unit}"
    );
    assert!(one_unit["peer_roll_pitch_rmse_deg"][1].is_null());
    // One unit's own filter averaged is that filter, turned by the mounting of the other
    // flights' four-unit averages (no other flight has unit 1 alone), as the fused solution is.
    assert!(number(&one_unit["peer_average"]["roll_pitch_rmse_deg"]).is_finite());
    assert!(one_unit["mahony"]["cross_validated"]["single_roll_pitch_rmse_deg"][1].is_null());
    let three_units = flights
        .iter()
        .find(|f| f["name"] == "Horizontal/path_7")
        .unwrap();
    assert_eq!(three_units["imus"], serde_json::json!([1, 2, 4]));
    assert!(three_units["madgwick"]["default"]["single_roll_pitch_rmse_deg"][2].is_null());
    assert!(number(&three_units["peer_average"]["roll_pitch_rmse_deg"]).is_finite());
}

#[test]
fn eval_quadrotor_gnss_and_outage_modes_report_their_figures() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    for mode in ["gnss", "outage"] {
        let report = report(&dir, mode, &[]);
        assert_eq!(report["mode"], mode);
        let trials = report["trials"].as_array().unwrap();
        assert!(!trials.is_empty(), "{report}");
        for key in [
            "roll_pitch_rmse_deg",
            "heading_rmse_deg",
            "horizontal_rmse_m",
        ] {
            assert!(number(&report[key]).is_finite(), "{key}: {report}");
        }
        // A GNSS-aided solution is held to metres, not the tens of metres of the free one.
        assert!(number(&report["horizontal_rmse_m"]) < 5.0, "{report}");
        // The units sit tilted by most of a degree on the airframe: with the mounting fitted on
        // the other flights, as the AHRS mode scores, the fused roll/pitch error is smaller, and
        // the in-sample fit (every flight) is no worse than the held-out one by much.
        let raw = number(&report["roll_pitch_rmse_deg"]);
        let mounted = number(&report["roll_pitch_rmse_mounted_deg"]);
        let in_sample = number(&report["roll_pitch_rmse_mounted_in_sample_deg"]);
        assert!(mounted < raw, "mounted {mounted} raw {raw}");
        assert!(
            in_sample <= mounted + 0.05,
            "in sample {in_sample}, held out {mounted}"
        );
        if mode == "outage" {
            assert!(number(&report["outage_error_m"]).is_finite(), "{report}");
            let single = report["single_outage_error_m"].as_array().unwrap();
            assert_eq!(single.len(), 4, "{report}");
        }
    }
}

#[test]
fn eval_quadrotor_gnss_live_repeats_every_flight_through_the_running_processes() {
    let Some(dir) = common::quadrotor_data_dir() else {
        return;
    };
    let report = report(&dir, "gnss", &["--live"]);
    let live = &report["live"];
    // The processes are the library code: the same frames and messages give the same attitude.
    assert!(
        number(&live["live_vs_same_input_max_diff_deg"]) < 1e-9,
        "{live}"
    );
    assert_eq!(live["live_rows_missing"].as_u64(), Some(0), "{live}");
    // Against the in-process run only the counts and fusion's fault detection differ: the mean
    // figure agrees to far below its own precision.
    let in_process = number(&report["roll_pitch_rmse_mounted_deg"]);
    let from_service = number(&live["live_roll_pitch_rmse_deg"]);
    assert!(
        (in_process - from_service).abs() < 0.01,
        "{in_process} vs {from_service}"
    );
    for t in report["trials"].as_array().unwrap() {
        assert!(t["live"].is_object(), "{t}");
    }
}
