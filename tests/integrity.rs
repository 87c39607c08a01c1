//! Integrity of the navigation solution end to end: a device played by the test (a pseudo-terminal
//! speaking the wire protocol) feeds `rins up --port`, and the navigation stream must say what is
//! wrong when the input goes wrong — never "navigating" while it is — and come back to `ok` when
//! the input is right again, without an operator.
//!
//! Times are the device's (the frames' own clock), so a loaded machine changes nothing but the
//! wall-clock length of a test. Bounds: the integrity must leave `ok` within 0.1 s of the input
//! going wrong (the invalid limit is 50 ms of IMU outage); it must be `ok` again within the
//! recovery chain's length after the input is right: fusion's re-admission hold (1 s) when every
//! channel was out, the navigator's recovery hold (1 s), the next aiding updates, plus 1 s margin.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};
use std::time::Duration;

use common::device::{DeviceTick, FakeDevice};
use common::topic_stream::TopicStream;
use common::{Isolated, PipelineSlot, spawn_up, stop_up};
use ipc_types::{Integrity, NavMode, integrity_reason as why};
use rins_protocol::Payload;
use rins_sim::Scenario;
use serde_json::Value;

/// When the device misbehaves, device seconds.
const FAULT_AT_S: f64 = 8.0;
/// The integrity must have left `ok` this soon after the input went wrong, s.
const DETECT_WITHIN_S: f64 = 0.1;
/// Longest wall-clock wait for any one condition.
const WAIT: Duration = Duration::from_secs(90);

fn device_s(v: &Value) -> f64 {
    v["header"]["origin_device_time_us"]
        .as_f64()
        .unwrap_or(f64::NAN)
        * 1e-6
}

/// The sample's integrity; one that cannot be read counts as invalid.
fn integrity(v: &Value) -> Integrity {
    let value = v["integrity"].as_u64().and_then(|i| u8::try_from(i).ok());
    value
        .and_then(Integrity::from_u8)
        .unwrap_or(Integrity::Invalid)
}

/// The sample's mode, `None` when it cannot be read.
fn mode(v: &Value) -> Option<NavMode> {
    let value = v["mode"].as_u64().and_then(|m| u8::try_from(m).ok());
    value.and_then(NavMode::from_u8)
}

fn reasons(v: &Value) -> u32 {
    v["integrity_reasons"].as_u64().unwrap_or(0) as u32
}

/// What the navigation stream did around one misbehaviour of the device.
struct Episode {
    /// The first sample after the fault that is not `ok`.
    first_bad: Value,
    /// The worst integrity seen during the fault, and every reason seen.
    worst: Integrity,
    reasons: u32,
    /// The first `ok` sample after the fault ended.
    back_ok: Value,
    summary: Value,
}

/// Runs the pipeline on a device whose ticks from `FAULT_AT_S` to `FAULT_AT_S + duration_s` go
/// through `fault`, and follows the navigation stream through it.
fn episode(
    name: &str,
    duration_s: f64,
    fault: impl Fn(f64, &mut DeviceTick) + Send + 'static,
) -> Episode {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new(name);
    let end = FAULT_AT_S + duration_s;
    let device = FakeDevice::start(Scenario::Static, move |mut tick| {
        if (FAULT_AT_S..end).contains(&tick.t_s) {
            fault(tick.t_s - FAULT_AT_S, &mut tick);
        }
    });
    let up = spawn_up(&ipc, &["--port", device.tty(), "--json"]);
    let nav = TopicStream::start(&ipc, "nav");
    let (before, _) = nav.wait_for("ok before the fault", 0, WAIT, |v| {
        integrity(v) == Integrity::Ok && mode(v) == Some(NavMode::Navigating)
    });
    let (i, _) = nav.wait_for("at the fault", before, WAIT, |v| device_s(v) >= FAULT_AT_S);
    let (_, first_bad) = nav.wait_for("not ok after the fault", i, WAIT, |v| {
        integrity(v) != Integrity::Ok
    });
    let (j, _) = nav.wait_for("after the fault", i, WAIT, |v| device_s(v) >= end);
    let (_, back_ok) = nav.wait_for("ok after the fault", j, WAIT, |v| {
        integrity(v) == Integrity::Ok
    });
    let during = nav.since(i);
    let during = during
        .iter()
        .take_while(|v| device_s(v) < device_s(&back_ok));
    let (mut worst, mut all_reasons) = (Integrity::Ok, 0);
    for v in during {
        worst = worst.max(integrity(v));
        all_reasons |= reasons(v);
        // Never navigating while invalid, in any sample.
        if integrity(v) == Integrity::Invalid {
            assert_eq!(mode(v), Some(NavMode::Invalid), "{v}");
            assert_eq!(v["aiding"].as_u64().unwrap_or(0) & 0xff, 0, "{v}");
        }
    }
    drop(nav);
    let summary = stop_up(&ipc, up);
    // For the record (`cargo test --test integrity -- --nocapture`).
    eprintln!(
        "{name}: not ok {:.3} s after the fault, worst {}, reasons {}; ok again {:.3} s after it ended; \
         integrity samples {}",
        device_s(&first_bad) - FAULT_AT_S,
        worst.name(),
        why::describe(all_reasons),
        device_s(&back_ok) - end,
        summary["nav_integrity_samples"]
    );
    Episode {
        first_bad,
        worst,
        reasons: all_reasons,
        back_ok,
        summary,
    }
}

fn imu<'t>(tick: &'t mut DeviceTick<'_>) -> &'t mut rins_protocol::ImuFrame {
    match &mut tick.frames[0].payload {
        Payload::Imu(f) => f,
        _ => panic!("the first frame of a tick is the IMU's"),
    }
}

fn assert_detected(e: &Episode, reason: u32) {
    let t = device_s(&e.first_bad);
    assert!(
        t <= FAULT_AT_S + DETECT_WITHIN_S,
        "integrity left ok only at {t} s: {}",
        e.first_bad
    );
    assert_eq!(
        e.worst,
        Integrity::Invalid,
        "reasons {}",
        why::describe(e.reasons)
    );
    assert!(
        e.reasons & reason != 0,
        "reasons seen: {}",
        why::describe(e.reasons)
    );
}

fn assert_back_within(e: &Episode, fault_s: f64, within_s: f64) {
    let t = device_s(&e.back_ok);
    assert!(
        t <= FAULT_AT_S + fault_s + within_s,
        "ok again only at {t} s (fault ended at {} s)",
        FAULT_AT_S + fault_s
    );
    assert_eq!(mode(&e.back_ok), Some(NavMode::Navigating), "{}", e.back_ok);
}

#[test]
fn every_channel_invalid_for_five_seconds_is_invalid_then_recovers_without_an_operator() {
    let e = episode("ig_invalid", 5.0, |_, tick| {
        imu(tick).valid_mask = 0;
    });
    assert_detected(&e, why::IMU_UNUSABLE);
    // Fusion's re-admission hold, the navigator's recovery, the next updates, margin.
    assert_back_within(&e, 5.0, 3.5);
    // The altitude did not run away while nothing was integrated.
    let alt = e.back_ok["altitude_m"].as_f64().unwrap();
    assert!((alt - 488.0).abs() < 5.0, "altitude {alt}");
    assert_eq!(e.summary["restarts"], 0, "{}", e.summary);
}

#[test]
fn the_whole_block_at_full_scale_is_a_block_fault_not_motion() {
    // +full scale for 3 s, then −full scale for 3 s, every gyro and accelerometer channel.
    let e = episode("ig_full", 6.0, |dt, tick| {
        let count = if dt < 3.0 { 2047 } else { -2048 };
        let f = imu(tick);
        f.gyro_counts[..4].fill(count);
        f.accel_counts[..4].fill(count);
    });
    assert_detected(&e, why::IMU_UNUSABLE);
    assert_back_within(&e, 6.0, 2.5);
    let alt = e.back_ok["altitude_m"].as_f64().unwrap();
    assert!((alt - 488.0).abs() < 5.0, "altitude {alt}");
    assert_eq!(e.summary["restarts"], 0, "{}", e.summary);
}

#[test]
fn gyros_at_full_scale_do_not_turn_the_heading() {
    let e = episode("ig_gyro", 5.0, |_, tick| {
        imu(tick).gyro_counts[..4].fill(2047);
    });
    assert_detected(&e, why::IMU_UNUSABLE);
    assert_back_within(&e, 5.0, 2.5);
    let q: Vec<f64> = (0..4)
        .map(|i| e.back_ok["quaternion"][i].as_f64().unwrap())
        .collect();
    let yaw = (2.0 * (q[0] * q[3] + q[1] * q[2]))
        .atan2(1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]))
        .to_degrees();
    // The static scenario's heading is 30°: the magnetometer holds it within its σ.
    assert!((yaw - 30.0).abs() < 3.0, "yaw {yaw}");
}

#[test]
fn a_block_of_the_wrong_shape_is_invalid_input_and_fusion_is_not_restarted() {
    // 16 gyros and 16 accelerometers for 2 s, then 3 and 3 for 2 s: valid frames of another
    // sensor block.
    let phase = Arc::new(AtomicU8::new(0));
    let seen = Arc::clone(&phase);
    let e = episode("ig_shape", 4.0, move |dt, tick| {
        let n = if dt < 2.0 { 16 } else { 3 };
        seen.store(n, Ordering::Relaxed);
        let f = imu(tick);
        let (g, a) = (f.gyro_counts[0], f.accel_counts[0]);
        f.n_gyro = n;
        f.n_accel = n;
        f.gyro_counts[..usize::from(n)].fill(g);
        f.accel_counts[..usize::from(n)].fill(a);
        f.valid_mask = if n == 16 {
            u32::MAX
        } else {
            0b111 | 0b111 << 16
        };
    });
    assert_eq!(phase.load(Ordering::Relaxed), 3, "both shapes were sent");
    assert_detected(&e, why::IMU_UNUSABLE);
    assert_back_within(&e, 4.0, 2.5);
    // The stall was upstream: fusion answered every frame, the watchdog restarted nothing.
    assert_eq!(e.summary["restarts"], 0, "{}", e.summary);
}

/// `rins up ARGS --json` on the simulator, one pipeline slot held: the checked summary.
fn up_summary(test: &str, args: &[&str]) -> Value {
    let _slot = PipelineSlot::take();
    common::up_json(test, args)
}

/// A 0.02 rad/s bias on one of four gyros: a one-dimensional parity space detects it but cannot
/// say which channel it is. Fusion's windowed parity mean declares it within a tenth of a second
/// (the per-sample test took 3.6 s, while the attitude integrated 3° of error and the integrity
/// said ok), and no sample the integrity calls ok is off by more than the fault-free flight's
/// own error (1.24° at 45 s).
#[test]
fn a_gyro_bias_is_declared_at_once_and_no_sample_called_ok_carries_its_error() {
    let s = up_summary(
        "ig_bias",
        &[
            "--scenario",
            "uav",
            "--duration",
            "25",
            "--inject",
            "gyro2:bias=0.02@8s",
        ],
    );
    let fault = &s["faults"][0];
    let injected = fault["injected_at_s"].as_f64().expect("injected");
    let detected = fault["detected_at_s"].as_f64().expect("detected");
    assert!(detected - injected < DETECT_WITHIN_S, "{fault}");
    assert!(fault["isolated_at_s"].as_f64().is_some(), "{fault}");
    let while_ok = common::num(&s, "att_err_deg_max_while_ok");
    assert!(while_ok < 1.5, "{while_ok}° while ok: {s}");
    assert_eq!(common::num(&s, "false_alarms"), 0.0, "{s}");
}

/// A configuration that names no initial position (here: only an alignment setting) starts the
/// navigator at a placeholder (0°, 0°), 5 300 km from the simulator's origin: the horizontal
/// solution is never called ok, and the summary has no "while ok" horizontal error to show.
#[test]
fn without_an_initial_position_no_sample_is_ok() {
    let config = common::TempFile::new("ig-partial", "toml", "[navigator]\nalign_s = 1.0\n");
    let s = up_summary(
        "ig_nopos",
        &[
            "--scenario",
            "static",
            "--duration",
            "6",
            "--config",
            config.path(),
        ],
    );
    let samples = &s["nav_integrity_samples"];
    assert_eq!(samples["ok"], 0, "{s}");
    assert!(samples["degraded"].as_u64().unwrap_or(0) > 1000, "{s}");
    assert!(s.get("horiz_err_m_max_while_ok").is_none(), "{s}");
}
