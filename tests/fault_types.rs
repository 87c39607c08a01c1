//! Every fault type, injected through the simulator into the running pipeline: each must be found
//! and (where the design says it can be) isolated in time, with no false alarm on the other
//! channels, while navigation carries on. Two faults per run (one gyro, one accelerometer), so the
//! four-channel block keeps three good channels of each type.

mod common;

use common::{Isolated, last_json, num};
use serde_json::Value;

/// Runs the pipeline with the given faults and returns the summary, after checking that nothing was
/// lost, nothing else alarmed, and navigation went on with attitude error below `att_max_deg`.
fn run_with_faults(
    test: &str,
    scenario: &str,
    duration: &str,
    faults: &[&str],
    att_max_deg: f64,
) -> Value {
    let ipc = Isolated::new(test);
    let mut args = vec![
        "up",
        "--scenario",
        scenario,
        "--duration",
        duration,
        "--json",
    ];
    for f in faults {
        args.extend(["--inject", f]);
    }
    let out = ipc.run(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let s = last_json(&out);
    assert_eq!(num(&s, "false_alarms"), 0.0, "{s}");
    common::assert_no_loss_beyond_the_line(&s);
    // Navigation carried on through the faults: an output for every frame but the last few that were
    // still in the pipeline when the shutdown stopped it (`dropped` counts gaps in between), and
    // attitude still good.
    assert!(num(&s, "nav_samples") >= num(&s, "frames") - 20.0, "{s}");
    assert!(num(&s, "att_err_deg_max") < att_max_deg, "{s}");
    s
}

fn fault<'a>(summary: &'a Value, channel: &str) -> &'a Value {
    summary["faults"]
        .as_array()
        .and_then(|f| f.iter().find(|f| f["channel"] == channel))
        .unwrap_or_else(|| panic!("no fault on {channel} in {summary}"))
}

/// Seconds from injection to detection and to isolation (None when it did not happen).
fn delays(f: &Value) -> (Option<f64>, Option<f64>) {
    let at = f["injected_at_s"].as_f64().expect("injected");
    (
        f["detected_at_s"].as_f64().map(|t| t - at),
        f["isolated_at_s"].as_f64().map(|t| t - at),
    )
}

/// At rest the zero-rate / gravity reference names a fault channel as soon as the parity test fires,
/// which can be before the channel-health check for that fault type has enough samples.
const AT_REST: &str = "stationary-reference";

fn assert_isolated_within(f: &Value, limit_s: f64, reasons: &[&str]) {
    let (detected, isolated) = delays(f);
    let isolated = isolated.unwrap_or_else(|| panic!("not isolated: {f}"));
    assert!(detected.is_some_and(|d| d <= isolated), "{f}");
    assert!(
        isolated <= limit_s,
        "isolated after {isolated} s > {limit_s} s: {f}"
    );
    assert!(
        reasons.iter().any(|r| f["reason"] == *r),
        "reason not in {reasons:?}: {f}"
    );
}

#[test]
fn at_rest_stuck_and_saturated_channels_are_isolated_within_20_ms() {
    let s = run_with_faults(
        "stuck_sat",
        "static",
        "6",
        &["gyro1:stuck@3s", "accel2:saturate@3s"],
        0.5,
    );
    assert_isolated_within(fault(&s, "gyro1"), 0.020, &["stuck", AT_REST]);
    assert_isolated_within(fault(&s, "accel2"), 0.020, &["saturated", AT_REST]);
}

#[test]
fn in_flight_stuck_and_saturated_channels_are_isolated_by_channel_health() {
    // At 20 s the vehicle is climbing out, rotating: no zero-rate reference, four channels, so parity
    // alone cannot name the gyro; the stuck check must. In unaccelerated climb the specific force is
    // constant, so the gravity reference may name the saturated accelerometer first.
    let s = run_with_faults(
        "stuck_sat_uav",
        "uav",
        "23",
        &["gyro1:stuck@20s", "accel2:saturate@20s"],
        2.0,
    );
    assert_isolated_within(fault(&s, "gyro1"), 0.020, &["stuck"]);
    assert_isolated_within(fault(&s, "accel2"), 0.020, &["saturated", AT_REST]);
}

#[test]
fn bias_step_is_detected_within_10_ms_and_isolated_at_rest_and_dead_accelerometer_at_once() {
    // 0.05 rad/s is about 9σ of the gyro parity noise (σ ≈ 0.0055 rad/s per channel).
    let s = run_with_faults(
        "bias_dead",
        "static",
        "6",
        &["gyro0:bias=0.05@3s", "accel3:dead@3s"],
        0.5,
    );
    let gyro = fault(&s, "gyro0");
    let (detected, _) = delays(gyro);
    assert!(detected.is_some_and(|d| d <= 0.010), "{gyro}");
    // Four channels: parity cannot say which; at rest the zero-rate reference can.
    assert_isolated_within(gyro, 0.5, &[AT_REST]);
    assert_isolated_within(fault(&s, "accel3"), 0.002, &["missing"]);
}

#[test]
fn noisy_and_intermittent_channels_are_isolated() {
    let s = run_with_faults(
        "noise_interm",
        "static",
        "6",
        &["gyro2:noise=20@3s", "accel1:intermittent=0.2@3s"],
        0.5,
    );
    // The noise check compares 200-sample windows: at most two windows at 1 kHz.
    assert_isolated_within(fault(&s, "gyro2"), 0.45, &["noisy", AT_REST]);
    // The first dropout marks the channel missing.
    assert_isolated_within(fault(&s, "accel1"), 0.002, &["missing"]);
}

#[test]
fn ramping_gyro_and_accelerometer_bias_are_caught() {
    // Until the ramp is detected its bias enters the solution: allow the attitude error it causes
    // (about 0.5·ramp·t²·projection ≈ 0.3° after 0.6 s).
    let s = run_with_faults(
        "ramp_bias",
        "static",
        "6",
        &["gyro3:ramp=0.05@3s", "accel0:bias=0.5@3s"],
        1.0,
    );
    // A 0.05 rad/s/s ramp crosses ~5σ of the parity noise after about 0.6 s.
    let (detected, _) = delays(fault(&s, "gyro3"));
    assert!(detected.is_some_and(|d| d < 1.5), "{s}");
    // 0.5 m/s² is about 10σ of the accelerometer parity noise.
    let accel = fault(&s, "accel0");
    let (detected, _) = delays(accel);
    assert!(detected.is_some_and(|d| d <= 0.010), "{accel}");
    assert_isolated_within(accel, 0.5, &[AT_REST]);
}
