//! `rins plot`: a synthetic recording (navigation with a slowly turning attitude, truth a little
//! off it, a gyro excluded half-way, one injected fault, stage stamps) gives the five PNG files at
//! their size; a recording of navigation only gives the plots it can and names the others.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use image::GenericImageView;
use ipc_types::{
    ChannelState, FaultApplied, FusedImu, Header, NavMode, NavState, SensorType, SimFault, Stage,
    Truth, names,
};
use rins_recording::{RecordOptions, Recorder};

const RINS: &str = env!("CARGO_BIN_EXE_rins");
const WIDTH: u32 = 1400;
const HEIGHT: u32 = 900;

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rins-plot-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The quaternion of a yaw about down, degrees.
fn yaw(deg: f64) -> [f64; 4] {
    let (s, c) = (deg.to_radians() / 2.0).sin_cos();
    [c, 0.0, 0.0, s]
}

/// Writes `seconds` of frames at `rate_hz` into `path`; truth and fusion only when asked.
fn write_recording(path: &Path, seconds: f64, rate_hz: f64, truth: bool, fused: bool) {
    let mut rec = Recorder::create(path, &RecordOptions::default()).unwrap();
    let nav_ch = rec.channel_for::<NavState>(names::NAV_LANES[0]).unwrap();
    let truth_ch = rec.channel_for::<Truth>(names::TRUTH).unwrap();
    let fused_ch = rec.channel_for::<FusedImu>(names::FUSED_IMU).unwrap();
    let fault_ch = rec
        .channel_for::<FaultApplied>(names::SIM_FAULT_APPLIED)
        .unwrap();
    let lat0 = 47.0f64.to_radians();
    let lon0 = 8.0f64.to_radians();
    let frames = (seconds * rate_hz) as u64;
    let fault_us = (seconds / 2.0 * 1e6) as u64 - 200_000;
    for i in 0..frames {
        let t_us = (i as f64 * 1e6 / rate_hz) as u64;
        let t = t_us as f64 / 1e6;
        let rx_ns = 5_000_000_000 + t_us * 1000;
        let mut header = Header {
            origin_seq: 70_000 + i,
            origin_device_time_us: t_us,
            origin_rx_ns: rx_ns,
            ..Header::default()
        };
        header.stamp(Stage::Acquisition, rx_ns + 40_000 + (i % 7) * 3_000);
        header.stamp(Stage::Fusion, rx_ns + 90_000 + (i % 11) * 4_000);
        let log_ns = rx_ns + 400_000;
        if truth {
            let t_msg = Truth {
                header: Header {
                    origin_seq: header.origin_seq,
                    origin_device_time_us: t_us,
                    ..Header::default()
                },
                quaternion: yaw(9.0 * t),
                latitude_rad: lat0 + t / 6_366_000.0,
                longitude_rad: lon0,
                altitude_m: 500.0,
                ..Truth::default()
            };
            rec.write_payload(truth_ch, log_ns, log_ns, &t_msg).unwrap();
        }
        if fused {
            let mut f = FusedImu {
                n_gyro: 4,
                n_accel: 4,
                header,
                ..FusedImu::default()
            };
            for c in 0..4 {
                f.gyro_state[c] = ChannelState::Ok as u8;
                f.accel_state[c] = ChannelState::Ok as u8;
            }
            if t_us >= fault_us + 100_000 {
                f.gyro_state[1] = ChannelState::Suspect as u8;
            }
            if t >= seconds / 2.0 {
                f.gyro_state[1] = ChannelState::Excluded as u8;
            }
            rec.write_payload(fused_ch, log_ns, log_ns, &f).unwrap();
            if t_us == fault_us {
                let applied = FaultApplied {
                    version: ipc_types::PAYLOAD_VERSION,
                    sensor: SensorType::Gyro as u8,
                    channel: 1,
                    fault: SimFault::Dead as u8,
                    device_time_us: fault_us,
                    ..FaultApplied::default()
                };
                rec.write_payload(fault_ch, log_ns, log_ns, &applied)
                    .unwrap();
            }
        }
        header.stamp(Stage::Navigator, rx_ns + 250_000 + (i % 13) * 5_000);
        let mut cov = [0.0; ipc_types::NAV_STATES];
        cov[..3].fill((0.5f64 + t / 10.0).to_radians().powi(2));
        cov[6..9].fill(1.0 + t);
        let nav = NavState {
            mode: NavMode::Navigating as u8,
            header,
            // Truth turned by half a degree, and a metre and a half north.
            quaternion: yaw(9.0 * t + 0.5),
            latitude_rad: lat0 + (t + 1.5) / 6_366_000.0,
            longitude_rad: lon0,
            altitude_m: 500.3,
            covariance_diag: cov,
            ..NavState::default()
        };
        rec.write_payload(nav_ch, log_ns, log_ns, &nav).unwrap();
    }
    rec.finish().unwrap();
}

/// Runs `rins plot FILE --out DIR --json`; the JSON of its last line.
fn plot(file: &Path, out: &Path) -> serde_json::Value {
    let output = Command::new(RINS)
        .arg("plot")
        .arg(file)
        .arg("--out")
        .arg(out)
        .arg("--json")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!stderr.contains("damaged"), "{stderr}");
    serde_json::from_str(stdout.lines().last().unwrap()).unwrap()
}

fn names_of(list: &serde_json::Value, key: Option<&str>) -> Vec<String> {
    list.as_array()
        .unwrap()
        .iter()
        .map(|v| {
            let v = key.map_or(v, |k| &v[k]);
            let s = v.as_str().unwrap();
            Path::new(s)
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect()
}

fn assert_png(path: &Path) {
    let image = image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(image.dimensions(), (WIDTH, HEIGHT), "{}", path.display());
}

#[test]
fn a_full_recording_gives_five_plots() {
    let dir = scratch("full");
    let file = dir.join("run.mcap");
    write_recording(&file, 20.0, 100.0, true, true);
    let out = dir.join("plots/new");
    let start = Instant::now();
    let json = plot(&file, &out);
    eprintln!("20 s at 100 Hz plotted in {:?}", start.elapsed());
    let written = names_of(&json["written"], None);
    assert_eq!(
        written,
        [
            "attitude.png",
            "position.png",
            "errors.png",
            "channels.png",
            "latency.png"
        ],
        "{json}"
    );
    assert!(json["skipped"].as_array().unwrap().is_empty(), "{json}");
    for name in &written {
        assert_png(&out.join(name));
    }
    if std::env::var_os("RINS_PLOT_KEEP").is_none() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn without_truth_and_fusion_the_missing_plots_are_named() {
    let dir = scratch("navonly");
    let file = dir.join("run.mcap");
    write_recording(&file, 5.0, 100.0, false, false);
    let out = dir.join("plots");
    let json = plot(&file, &out);
    let written = names_of(&json["written"], None);
    // Without truth the error plot still shows the filter's own bounds.
    assert_eq!(
        written,
        ["attitude.png", "position.png", "errors.png", "latency.png"],
        "{json}"
    );
    assert_eq!(
        names_of(&json["skipped"], Some("plot")),
        ["channels.png"],
        "{json}"
    );
    let reason = json["skipped"][0]["reason"].as_str().unwrap();
    assert!(reason.contains(names::FUSED_IMU), "{reason}");
    for name in &written {
        assert_png(&out.join(name));
    }
    if std::env::var_os("RINS_PLOT_KEEP").is_none() {
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn a_symbolic_link_as_output_is_refused() {
    let dir = scratch("link");
    let file = dir.join("run.mcap");
    write_recording(&file, 1.0, 100.0, false, false);
    let link = dir.join("out");
    std::os::unix::fs::symlink(&dir, &link).unwrap();
    let output = Command::new(RINS)
        .arg("plot")
        .arg(&file)
        .arg("--out")
        .arg(&link)
        .output()
        .unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("symbolic link"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Ten minutes at 1 kHz: how long the plots take (`--ignored`, a measurement).
#[test]
#[ignore]
fn ten_minutes_at_a_kilohertz() {
    let dir = scratch("long");
    let file = dir.join("run.mcap");
    write_recording(&file, 600.0, 1000.0, true, true);
    let start = Instant::now();
    let json = plot(&file, &dir.join("plots"));
    eprintln!(
        "600 s at 1 kHz ({} bytes) plotted in {:?}",
        std::fs::metadata(&file).unwrap().len(),
        start.elapsed()
    );
    assert_eq!(json["written"].as_array().unwrap().len(), 5, "{json}");
    std::fs::remove_dir_all(&dir).unwrap();
}
