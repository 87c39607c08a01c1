//! `rins bench rates`: the pipeline at a slow and a fast IMU rate, with no false alarm and the
//! injected faults detected and isolated at both, one JSON row per rate.

mod common;

use common::{Isolated, PipelineSlot};

#[test]
fn a_slow_and_a_fast_rate_have_no_false_alarm_and_isolate_the_faults() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("benchrates");
    let out = ipc.run_with_timeout(
        &[
            "bench",
            "rates",
            "--rates",
            "250,4000",
            "--duration",
            "10",
            "--json",
        ],
        std::time::Duration::from_secs(400),
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("[6/6] 4000 Hz"),
        "progress is shown: {stderr}"
    );
    let rows: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON row per line"))
        .collect();
    assert_eq!(rows.len(), 2, "{rows:?}");
    for (row, rate) in rows.iter().zip([250.0, 4000.0]) {
        assert_eq!(row["rate_hz"], rate, "{row}");
        assert_eq!(row["false_alarms"], 0, "{row}");
        assert_eq!(row["fault_run_false_alarms"], 0, "{row}");
        assert_eq!(row["dropped"], 0, "{row}");
        // The per-sample σ follows the density: 0.01 °/s/√Hz · √rate.
        let sigma = row["gyro_sigma_rps"].as_f64().unwrap();
        let expected = 0.01f64.to_radians() * f64::sqrt(rate);
        assert!((sigma / expected - 1.0).abs() < 1e-9, "{row}");
        let faults = row["faults"].as_array().unwrap();
        assert_eq!(faults.len(), 3, "{row}");
        for f in faults {
            assert_eq!(f["detected"], true, "{f}");
            assert_eq!(f["isolated"], true, "{f}");
        }
        // The bias is ten per-sample σ at the rate.
        let bias = faults.iter().find(|f| f["kind"] == "bias").unwrap();
        let b = bias["param"].as_f64().unwrap();
        assert!(b >= 10.0 * sigma && b < 10.01 * sigma, "{bias}");
    }
}
