//! Quadrotor loader on small files written by the test: missing files, malformed lines, lags,
//! repairs; and the evaluations listing the trials they cannot use.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use rins_eval::datasets::DatasetError;
use rins_eval::datasets::quadrotor::repair::COUNTER_WRAP_S;
use rins_eval::datasets::quadrotor::{list_trials, load_each, load_trial, total_repairs};

/// A fresh directory under the system temp dir, removed on drop.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("rins-eval-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        Self(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Rate about the sensor x axis, °/s, at row j of IMU `delay` rows late.
fn rate(j: i64) -> f64 {
    let t = j as f64 / 120.0;
    30.0 * (2.0 * t).sin() + 10.0 * (5.3 * t).cos()
}

fn write_imu(dir: &Path, imu: usize, rows: usize, delay: i64) {
    write_imu_timed(dir, imu, rows, delay, |j| j as f64 / 120.0);
}

/// [`write_imu`] with row j stamped `time(j)`.
fn write_imu_timed(dir: &Path, imu: usize, rows: usize, delay: i64, time: impl Fn(i64) -> f64) {
    let mut s = String::from("time,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z\n");
    for j in 0..rows as i64 {
        let t = time(j);
        let _ = writeln!(
            s,
            "{t},1.0,-2.0,30.0,0.1,0.2,9.8,{},{},{}",
            rate(j - delay),
            0.5 * rate(j - delay + 40),
            -2.0
        );
    }
    std::fs::write(dir.join(format!("IMU_{imu}.csv")), s).unwrap();
}

fn write_truth(dir: &Path, rows: usize) {
    let mut s = String::from(
        "time,distance(meters),speed(m/s), compass_heading(degrees), pitch(degrees), roll(degrees),height_above_takeoff(meters),North,East,Down\n",
    );
    for k in 0..rows {
        let t = k as f64 / 10.0;
        let _ = writeln!(
            s,
            "{t},{},2.0,90.0,2.0,1.0,5.0,0.0,{},0.0",
            2.0 * t,
            2.0 * t
        );
    }
    std::fs::write(dir.join("GT.csv"), s).unwrap();
}

#[test]
fn missing_imu_files_are_skipped_with_a_note_and_lags_are_removed() {
    let root = TempDir::new("missing");
    let trial_dir = root.0.join("Vertical").join("path_2");
    std::fs::create_dir_all(&trial_dir).unwrap();
    write_imu(&trial_dir, 1, 600, 0);
    write_imu(&trial_dir, 3, 600, 4);
    write_truth(&trial_dir, 50);

    let listed = list_trials(&root.0).unwrap();
    assert_eq!(listed.len(), 1);
    assert_eq!(listed[0].name, "Vertical/path_2");
    assert_eq!(listed[0].imus, vec![1, 3]);
    assert!(listed[0].has_truth);

    let trial = load_trial(&trial_dir).unwrap();
    assert_eq!(trial.imus.iter().map(|s| s.imu).collect::<Vec<_>>(), [1, 3]);
    assert!(
        trial.notes.iter().any(|n| n.contains("IMU_2.csv missing")),
        "{:?}",
        trial.notes
    );
    assert!(
        trial.notes.iter().any(|n| n.contains("IMU_4.csv missing")),
        "{:?}",
        trial.notes
    );
    assert_eq!(trial.imus[1].lag_rows, 4);
    // Aligned: the same instant in both series, so equal rates; 4 rows lost at the start.
    assert_eq!(trial.len(), 596);
    for (a, b) in trial.imus[0].samples.iter().zip(&trial.imus[1].samples) {
        assert_eq!(a.t_s, b.t_s);
        assert!((a.gyro_rps[0] - b.gyro_rps[0]).abs() < 1e-12);
    }
    // SI and FRD: −2 °/s about sensor z (up) is +2 °/s about FRD z (down); Acc_Z 9.8 → −9.8.
    let s = trial.imus[0].samples[10];
    assert!((s.gyro_rps[2] - 2f64.to_radians()).abs() < 1e-12);
    assert_eq!(s.accel_mps2, [0.1, -0.2, -9.8]);
    assert!(
        (s.euler_rad[1] - 2f64.to_radians()).abs() < 1e-12,
        "pitch = −Euler_Y"
    );
    assert!((trial.truth[3].heading_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn a_malformed_line_names_file_and_line() {
    let root = TempDir::new("malformed");
    write_imu(&root.0, 1, 300, 0);
    write_truth(&root.0, 30);
    let path = root.0.join("IMU_1.csv");
    let mut text = std::fs::read_to_string(&path).unwrap();
    text = text.replacen("0.1,0.2,9.8", "0.1,abc,9.8", 1);
    std::fs::write(&path, text).unwrap();
    let e = load_trial(&root.0).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("IMU_1.csv:2: Acc_Y = \"abc\""),
        "{message}"
    );
    assert!(matches!(e, DatasetError::Malformed { line: 2, .. }));
}

#[test]
fn a_trial_without_truth_or_without_imus_is_an_error() {
    let root = TempDir::new("incomplete");
    write_truth(&root.0, 30);
    let e = load_trial(&root.0).unwrap_err();
    assert!(matches!(e, DatasetError::MissingFile { .. }), "{e}");
    write_imu(&root.0, 2, 300, 0);
    std::fs::remove_file(root.0.join("GT.csv")).unwrap();
    let e = load_trial(&root.0).unwrap_err();
    assert!(e.to_string().contains("GT.csv: missing"), "{e}");
}

#[test]
fn a_short_file_is_an_error_and_time_going_back_cuts_the_file() {
    let root = TempDir::new("short");
    write_imu(&root.0, 1, 50, 0);
    write_truth(&root.0, 30);
    let e = load_trial(&root.0).unwrap_err();
    assert!(matches!(e, DatasetError::TooShort { rows: 50, .. }), "{e}");
    write_imu(&root.0, 1, 300, 0);
    let path = root.0.join("IMU_1.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replacen("\n0.5,", "\n0.1,", 1);
    std::fs::write(&path, text).unwrap();
    // Row 60 (0.5 s) stamped 0.1 s: rows 0..60 and the stray row are dropped, the 239 rows after
    // it (a gap of 49 periods from 0.1 s, too long to fill) kept.
    let trial = load_trial(&root.0).unwrap();
    assert_eq!(trial.len(), 239);
    assert_eq!(trial.repairs.rows_dropped, 61);
    assert!((trial.imus[0].samples[0].t_s - 61.0 / 120.0).abs() < 1e-9);
    assert!(
        trial.notes.iter().any(|n| n.contains("61 rows dropped")),
        "{:?}",
        trial.notes
    );
}

#[test]
fn a_counter_wrap_in_a_file_is_unwrapped() {
    let root = TempDir::new("wrap");
    // The counter wraps 1 s into the file.
    let start = COUNTER_WRAP_S - 1.0;
    write_imu_timed(&root.0, 1, 600, 0, |j| {
        ((start + j as f64 / 120.0) * 1e6)
            .round()
            .rem_euclid(COUNTER_WRAP_S * 1e6)
            / 1e6
    });
    write_truth(&root.0, 30);
    let trial = load_trial(&root.0).unwrap();
    assert_eq!(trial.repairs.counter_wraps, 1);
    assert_eq!(trial.imus[0].repairs.counter_wraps, 1);
    assert_eq!(trial.len(), 600);
    let s = &trial.imus[0].samples;
    for (j, pair) in s.windows(2).enumerate() {
        assert!(
            (pair[1].t_s - pair[0].t_s - 1.0 / 120.0).abs() < 2e-6,
            "row {j}"
        );
    }
    assert!((s[599].t_s - (start + 599.0 / 120.0)).abs() < 2e-6);
}

#[test]
fn a_trial_with_only_imu_1_loads() {
    let root = TempDir::new("single");
    write_imu(&root.0, 1, 400, 0);
    write_truth(&root.0, 40);
    let trial = load_trial(&root.0).unwrap();
    assert_eq!(trial.imus.len(), 1);
    assert_eq!(trial.len(), 400);
    assert_eq!(trial.repairs.imu_files_skipped, 0);
    // A file that is not there is not a skipped unit, only a note.
    assert_eq!(
        trial
            .notes
            .iter()
            .filter(|n| n.contains("missing: skipped"))
            .count(),
        3
    );
}

#[test]
fn unusable_imu_files_are_skipped_and_counted() {
    let root = TempDir::new("unusable");
    write_imu(&root.0, 1, 400, 0);
    write_imu(&root.0, 2, 50, 0);
    write_imu(&root.0, 3, 400, 2);
    std::fs::write(root.0.join("IMU_4.csv"), "not,a,header\n1,2,3\n").unwrap();
    write_truth(&root.0, 40);
    let trial = load_trial(&root.0).unwrap();
    assert_eq!(trial.imus.iter().map(|s| s.imu).collect::<Vec<_>>(), [1, 3]);
    assert_eq!(trial.repairs.imu_files_skipped, 2);
    assert_eq!(trial.imus[1].lag_rows, 2);
    // Offsets per file: the truth's (not estimable here: 0) plus the unit's lag of 2 rows.
    assert_eq!(trial.truth_offset_s, 0.0);
    assert_eq!(trial.imus[0].truth_offset_s, 0.0);
    assert!((trial.imus[1].truth_offset_s - 2.0 / 120.0).abs() < 0.05 / 120.0);
    for k in [2, 4] {
        assert!(
            trial
                .notes
                .iter()
                .any(|n| n.starts_with(&format!("IMU_{k}.csv skipped"))),
            "{:?}",
            trial.notes
        );
    }
    // With no usable unit left the trial fails with the first unit's error.
    std::fs::write(root.0.join("IMU_1.csv"), "time\n").unwrap();
    std::fs::remove_file(root.0.join("IMU_3.csv")).unwrap();
    let e = load_trial(&root.0).unwrap_err();
    assert!(e.to_string().contains("IMU_1.csv:1: header"), "{e}");
}

#[test]
fn load_each_keeps_the_trials_that_load() {
    let root = TempDir::new("each");
    for n in 1..=3 {
        let dir = root.0.join("Horizontal").join(format!("path_{n}"));
        std::fs::create_dir_all(&dir).unwrap();
        write_imu(&dir, 1, 300, 0);
        if n != 2 {
            write_truth(&dir, 30);
        }
    }
    let mut progress = Vec::new();
    let outcomes = load_each(&root.0, |d, t| progress.push((d, t))).unwrap();
    assert_eq!(progress, [(0, 3), (1, 3), (2, 3), (3, 3)]);
    let names: Vec<&str> = outcomes.iter().map(|(e, _)| e.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "Horizontal/path_1",
            "Horizontal/path_2",
            "Horizontal/path_3"
        ]
    );
    assert!(outcomes[0].1.is_ok() && outcomes[2].1.is_ok());
    let Err(e) = &outcomes[1].1 else {
        panic!("path_2 has no truth")
    };
    assert!(e.to_string().contains("path_2/GT.csv: missing"), "{e}");
    assert_eq!(total_repairs(&outcomes).trials_failed, 1);
}

/// A data set of three trials: one without truth, one with a single unit and one whose only
/// unit file is unreadable.
fn broken_data_set(root: &Path) {
    for n in 1..=3 {
        let dir = root.join("Horizontal").join(format!("path_{n}"));
        std::fs::create_dir_all(&dir).unwrap();
        write_imu(&dir, 1, 300, 0);
        if n != 1 {
            write_truth(&dir, 30);
        }
        if n == 3 {
            std::fs::write(dir.join("IMU_1.csv"), "time\n").unwrap();
        }
    }
}

#[test]
fn eval_fdi_lists_the_trials_it_cannot_use_instead_of_failing() {
    let root = TempDir::new("fdi-skip");
    broken_data_set(&root.0);
    let request = rins_eval::fdi::FdiRequest {
        dir: root.0.clone(),
        trials: Vec::new(),
        fdi: rins_fusion::FdiConfig::default(),
        lsb: [2.5e-3, 3.8e-2],
        threads: 1,
    };
    let mut last = (0, 0);
    let report = rins_eval::fdi::evaluate(&request, &mut |d, t| last = (d, t)).unwrap();
    assert_eq!(report.trials, 0);
    assert_eq!(last.0, last.1, "the progress ends at its total");
    let reasons: Vec<(&str, &str)> = report
        .skipped
        .iter()
        .map(|s| (s.trial.as_str(), s.reason.as_str()))
        .collect();
    assert_eq!(reasons.len(), 2, "{reasons:?}");
    assert!(reasons[0].1.contains("GT.csv: missing"), "{reasons:?}");
    assert!(reasons[1].1.contains("IMU_1.csv:1: header"), "{reasons:?}");
    assert_eq!(report.repairs.trials_failed, 2);
    // A single unit is not an error: it has no redundancy to monitor, and is listed as such.
    assert_eq!(report.single_unit.len(), 1);
    assert_eq!(report.single_unit[0].trial, "Horizontal/path_2");
    assert!(
        report.single_unit[0].reason.contains("no redundancy"),
        "{:?}",
        report.single_unit
    );
    let text = rins_eval::fdi::to_table(&report);
    assert!(
        text.contains("2 trials skipped:\n  Horizontal/path_1: "),
        "{text}"
    );
    let json = serde_json::to_value(&report).unwrap();
    assert_eq!(json["single_unit"][0]["trial"], "Horizontal/path_2");
}

#[test]
fn eval_quadrotor_lists_the_trials_it_cannot_use_instead_of_failing() {
    let root = TempDir::new("nav-skip");
    broken_data_set(&root.0);
    let config = rins_navigator::NavigatorConfig::default().aided_config();
    let report = rins_eval::quadrotor_nav::evaluate(&root.0, &config, &mut |_, _| ()).unwrap();
    // A single unit is enough to navigate: path_2 is evaluated, the other two are listed.
    let evaluated: Vec<&str> = report.trials.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(evaluated, ["Horizontal/path_2"]);
    let skipped: Vec<&str> = report.skipped.iter().map(|s| s.trial.as_str()).collect();
    assert_eq!(skipped, ["Horizontal/path_1", "Horizontal/path_3"]);
    assert_eq!(report.repairs.trials_failed, 2);
    // Constant truth angles give no timing information: the clock is kept, as the file's.
    assert_eq!(report.trials[0].unit_truth_offsets_s, [0.0]);
    let text = rins_eval::quadrotor_nav::report::to_table(&report);
    assert!(text.contains("trials skipped:"), "{text}");
    assert!(text.contains("Horizontal/path_1: "), "{text}");
    assert!(
        text.contains("truth clock +0.000 s (files: +0.000 s)"),
        "{text}"
    );
}
