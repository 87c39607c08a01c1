//! `rins import` end to end through the binary, on tiny data sets written here in each loader's
//! CSV layout (the public recordings are not needed): the files are written, read back by the
//! recording reader, their configuration is accepted by the loader, and a damaged trial is
//! skipped and named.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::Scratch;
use ipc_types::{RawImu, Truth, names};
use serde_json::Value;

fn rins(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rins"))
        .args(args)
        .output()
        .unwrap()
}

/// 12 s of one unit at 120 Hz in the Xsens DOT file layout (°/s, m/s²): rates in all three axes,
/// gravity and some manoeuvring force.
fn imu_csv() -> String {
    let mut text =
        String::from("time,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z\n");
    for j in 0..1440 {
        let t = j as f64 / 120.0;
        let gyro = [
            40.0 * (2.0 * t).sin(),
            20.0 * (3.1 * t).cos(),
            10.0 * (0.7 * t).sin(),
        ];
        let accel = [
            0.5 * (1.3 * t).cos(),
            0.3 * t.sin(),
            9.8 + 0.2 * (5.0 * t).sin(),
        ];
        text += &format!(
            "{t},1.0,2.0,30.0,{},{},{},{},{},{}\n",
            accel[0], accel[1], accel[2], gyro[0], gyro[1], gyro[2]
        );
    }
    text
}

/// 12 s of truth at 10 Hz in the GT.csv layout.
fn truth_csv() -> String {
    let mut text = String::from(
        "time,distance(meters),speed(m/s), compass_heading(degrees), pitch(degrees), roll(degrees),height_above_takeoff(meters),North,East,Down\n",
    );
    for i in 0..120 {
        let t = i as f64 / 10.0;
        text += &format!(
            "{t},{},2.0,90.0,{},{},{},{},0.0,{}\n",
            2.0 * t,
            -2.0 + (0.5 * t).sin(),
            3.0 * (0.3 * t).cos(),
            5.0 + 0.1 * t,
            2.0 * t,
            -0.1 * t
        );
    }
    text
}

/// A data set of one good flight (four units) and one whose only unit file is damaged.
fn quadrotor_data(dir: &Path) {
    let good = dir.join("Horizontal/path_1");
    std::fs::create_dir_all(&good).unwrap();
    let imu = imu_csv();
    for k in 1..=4 {
        std::fs::write(good.join(format!("IMU_{k}.csv")), &imu).unwrap();
    }
    std::fs::write(good.join("GT.csv"), truth_csv()).unwrap();
    let bad = dir.join("Horizontal/path_2");
    std::fs::create_dir_all(&bad).unwrap();
    std::fs::write(bad.join("IMU_1.csv"), "time,what\n1,2\n").unwrap();
    std::fs::write(bad.join("GT.csv"), truth_csv()).unwrap();
}

fn summary(out: &Output) -> Value {
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = stdout.lines().last().unwrap_or_default();
    serde_json::from_str(last)
        .unwrap_or_else(|e| panic!("{e}: {stdout}\n{}", String::from_utf8_lossy(&out.stderr)))
}

#[test]
fn a_quadrotor_data_set_becomes_recordings_with_configurations_and_the_damaged_trial_is_named() {
    let data = Scratch::new("import", "quadrotor-data");
    let out_dir = Scratch::new("import", "quadrotor-out");
    quadrotor_data(data.path());
    let out_path = out_dir.path().join("quad");
    let args = [
        "import",
        "quadrotor",
        data.path().to_str().unwrap(),
        out_path.to_str().unwrap(),
        "--json",
    ];
    let out = rins(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = summary(&out);
    assert_eq!(s["written"].as_array().unwrap().len(), 1, "{s}");
    let skipped = s["skipped"].as_array().unwrap();
    assert_eq!(skipped.len(), 1, "{s}");
    assert_eq!(skipped[0]["trial"], "Horizontal/path_2");
    let reason = skipped[0]["reason"].as_str().unwrap();
    assert!(reason.contains("path_2/IMU_1.csv"), "{reason}");
    assert_eq!(s["repairs"]["trials_skipped"], 1, "{s}");
    assert_eq!(s["config_errors"].as_array().unwrap().len(), 0, "{s}");

    let written = &s["written"][0];
    assert_eq!(written["channels"], 12);
    let frames = written["imu_frames"].as_u64().unwrap();
    assert!(frames > 1300, "{written}");

    // The recording reads back: every frame, 12 + 12 channels, device times 1/120 s apart.
    let mcap = out_path.join("Horizontal/path_1.mcap");
    let recording = rins_recording::read_file(&mcap).unwrap();
    assert_eq!(recording.skipped_count, 0);
    let imu: Vec<RawImu> = recording
        .messages
        .iter()
        .filter(|m| &*m.topic == names::RAW_IMU)
        .map(|m| m.decode().unwrap())
        .collect();
    let truth: Vec<Truth> = recording
        .messages
        .iter()
        .filter(|m| &*m.topic == names::TRUTH)
        .map(|m| m.decode().unwrap())
        .collect();
    assert_eq!(imu.len() as u64, frames);
    assert_eq!(
        truth.len() as u64,
        written["truth_samples"].as_u64().unwrap()
    );
    assert!(truth.len() > 100, "{}", truth.len());
    assert!(imu.iter().all(|f| f.n_gyro == 12 && f.n_accel == 12));
    assert!(imu.iter().all(|f| f.valid_mask == 0x0fff_0fff));
    for w in imu.windows(2) {
        let step = w[1].header.origin_device_time_us - w[0].header.origin_device_time_us;
        assert!((8333..=8334).contains(&step), "{step}");
        assert!(w[1].header.origin_rx_ns > w[0].header.origin_rx_ns);
    }
    // Identical units: every unit's channels carry the same counts.
    assert_eq!(imu[100].gyro_counts[0..3], imu[100].gyro_counts[9..12]);

    // The configuration beside it is a complete one the loader accepts, with the block's keys.
    let config_path = out_path.join("Horizontal/path_1.toml");
    let cfg = rins::config::load(Some(&config_path)).unwrap();
    let (gyro, accel) = cfg.geometries().unwrap();
    assert_eq!((gyro.n(), accel.n()), (12, 12));
    assert_eq!(cfg.fusion.rest_bias_s, 0.0);
    let start = cfg.navigator.start.expect("an in-flight start");
    assert!((start.time_s * 1e6).round() as u64 >= imu[0].header.origin_device_time_us);
    let text = std::fs::read_to_string(&config_path).unwrap();
    assert!(text.contains("converter_bits = 16"), "{text}");
    assert!(text.contains("Xsens DOT datasheet"), "{text}");

    let sidecar: Value = serde_json::from_str(
        &std::fs::read_to_string(out_path.join("Horizontal/path_1.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(sidecar["clock_offsets"].as_array().unwrap().len(), 5);

    // Again: refused, naming a file, unless --force.
    let again = rins(&args);
    assert!(!again.status.success());
    let err = String::from_utf8_lossy(&again.stderr);
    assert!(err.contains("path_1.mcap exists"), "{err}");
    assert!(err.contains("--force"), "{err}");
    let mut forced = args.to_vec();
    forced.push("--force");
    assert!(rins(&forced).status.success());
}

/// A pyshoe walk of 3 s at 200 Hz, z down, the foot moving along Vicon x.
fn walk_csv() -> String {
    let mut text = String::from(
        "t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyr_x_radps,gyr_y_radps,gyr_z_radps,gt_x_m,gt_y_m,gt_z_m\n",
    );
    for k in 0..600 {
        let t = (k + 1) as f64 / 200.0;
        text += &format!(
            "{t},{},0.2,-9.8,{},0.0,-0.002,{},2.0,0.1\n",
            (3.0 * t).sin(),
            0.5 * (4.0 * t).cos(),
            0.4 * t
        );
    }
    text
}

#[test]
fn pyshoe_walks_become_recordings_and_a_damaged_walk_is_named() {
    let data = Scratch::new("import", "pyshoe-data");
    let out_dir = Scratch::new("import", "pyshoe-out");
    std::fs::write(data.path().join("walk_a.csv"), walk_csv()).unwrap();
    let damaged = walk_csv().replacen("gyr_z_radps", "gyr_z_dps", 1);
    std::fs::write(data.path().join("walk_b.csv"), damaged).unwrap();
    let out = rins(&[
        "import",
        "pyshoe",
        data.path().to_str().unwrap(),
        out_dir.path().to_str().unwrap(),
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = summary(&out);
    assert_eq!(s["written"].as_array().unwrap().len(), 1, "{s}");
    assert_eq!(s["skipped"][0]["trial"], "walk_b", "{s}");
    assert!(
        s["skipped"][0]["reason"]
            .as_str()
            .unwrap()
            .contains("walk_b.csv"),
        "{s}"
    );
    let recording = rins_recording::read_file(out_dir.path().join("walk_a.mcap")).unwrap();
    let imu = recording
        .messages
        .iter()
        .filter(|m| &*m.topic == names::RAW_IMU)
        .count();
    assert_eq!(imu, 600);
    let cfg = rins::config::load(Some(&out_dir.path().join("walk_a.toml"))).unwrap();
    assert!(cfg.navigator.start.is_none());
    assert!(cfg.navigator.zupt.enabled, "the pedestrian profile");
}

#[test]
fn a_missing_data_set_is_named() {
    let out = rins(&["import", "quadrotor", "/nonexistent/quad", "/tmp/never"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/quad"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}
