//! `rins up --imu-rate`: the simulated block and every stage at another IMU rate, end to end with
//! nothing dropped; a rate out of range is refused naming the option.

mod common;

use common::{Isolated, fails_with, spawn_up_navigating, stop_up};

/// 2 kHz, twice the block's default: every frame the device sent reaches the navigation output,
/// and consecutive solutions are one 2 kHz period apart in device time.
#[test]
fn the_pipeline_carries_2_khz_without_a_drop() {
    let ipc = Isolated::new("rate2k");
    let up = spawn_up_navigating(
        &ipc,
        &[
            "--scenario",
            "uav",
            "--imu-rate",
            "2000",
            "--duration",
            "300",
            "--json",
        ],
    );
    let echo = ipc.run(&["echo", "nav", "--raw", "--count", "400", "--timeout", "60"]);
    assert!(echo.status.success(), "{echo:?}");
    let samples: Vec<serde_json::Value> = String::from_utf8_lossy(&echo.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("a JSON sample"))
        .collect();
    assert_eq!(samples.len(), 400);
    let (mut consecutive, mut at_period) = (0, 0);
    for pair in samples.windows(2) {
        let (a, b) = (&pair[0]["header"], &pair[1]["header"]);
        if b["origin_seq"].as_u64() == a["origin_seq"].as_u64().map(|s| s + 1) {
            consecutive += 1;
            let dt_us = b["origin_device_time_us"].as_u64().unwrap()
                - a["origin_device_time_us"].as_u64().unwrap();
            // The device clock counts whole microseconds: 500 µs a sample.
            if dt_us == 500 {
                at_period += 1;
            }
        }
    }
    assert_eq!(
        consecutive, 399,
        "a merged stream has every sequence number"
    );
    assert_eq!(at_period, 399);
    // Some seconds at the rate, then the run's own account of what was lost.
    std::thread::sleep(std::time::Duration::from_secs(8));
    let summary = stop_up(&ipc, up);
    eprintln!("{summary}");
    for key in ["dropped", "lost_frames", "crc_errors", "malformed_frames"] {
        assert_eq!(summary[key], 0, "{key}: {summary}");
    }
    // At least the 8 s at 2 kHz.
    let nav = summary["nav_samples"].as_u64().unwrap();
    assert!(nav >= 16_000, "{nav} navigation samples");
}

#[test]
fn a_rate_out_of_range_is_refused_naming_the_option() {
    fails_with(
        "rate0",
        &["up", "--imu-rate", "0", "--duration", "1"],
        &["--imu-rate 0", "Hz"],
    );
    fails_with(
        "ratenan",
        &["up", "--imu-rate", "NaN", "--duration", "1"],
        &["--imu-rate NaN"],
    );
}
