//! The device counters end to end: a device played by the test on a pseudo-terminal reorders,
//! repeats, jumps its sequence counter and its clock, and sends frames with a valid CRC around
//! malformed content; `rins up --port --json` must count each exactly, lose nothing it did not
//! lose, and the navigation output's device time must keep advancing through the clock jumps.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use common::device::{DeviceTick, FakeDevice, Malformed, malformed_frame};
use common::topic_stream::TopicStream;
use common::{Isolated, PipelineSlot, spawn_up, stop_up};
use rins_protocol::Payload;
use rins_sim::Scenario;

/// Device seconds after the first frame written at which each disturbance starts.
const REORDER_AT_S: [f64; 3] = [6.0, 6.5, 7.0];
const DUPLICATE_AT_S: [f64; 5] = [8.0, 8.2, 8.4, 8.6, 8.8];
const MALFORMED_AT_S: f64 = 10.0;
const MALFORMED: usize = 48;
const SEQ_JUMP_AT_S: f64 = 12.0;
const SEQ_JUMP: u16 = 30_000;
const CLOCK_FORWARD_AT_S: f64 = 15.0;
const CLOCK_FORWARD_US: u32 = 600_000_000;
const CLOCK_WRAP_AT_S: f64 = 18.0;
const CLOCK_WRAP_US: u32 = (1 << 31) + 1;
const END_S: f64 = 22.0;

/// The tamper: nothing is written until `go` (so the pipeline reads the stream from its first
/// frame: nothing lost before it opened the terminal), then the schedule above.
fn schedule(go: Arc<AtomicBool>) -> impl FnMut(DeviceTick) + Send + 'static {
    let mut start_s = None;
    let mut held = None;
    let mut done = [false; REORDER_AT_S.len() + DUPLICATE_AT_S.len()];
    let mut malformed_sent = 0;
    move |tick: DeviceTick| {
        if !go.load(Ordering::Relaxed) {
            tick.frames.clear();
            return;
        }
        let t = tick.t_s - *start_s.get_or_insert(tick.t_s);
        if let Some(frame) = held.take() {
            // Frame k after frame k + 1.
            tick.frames.insert(1, frame);
        }
        for (k, at) in REORDER_AT_S.iter().enumerate() {
            if t >= *at && !done[k] {
                done[k] = true;
                held = Some(tick.frames.remove(0));
                return;
            }
        }
        for (k, at) in DUPLICATE_AT_S.iter().enumerate() {
            let k = REORDER_AT_S.len() + k;
            if t >= *at && !done[k] {
                done[k] = true;
                tick.frames.insert(1, tick.frames[0]);
            }
        }
        if t >= MALFORMED_AT_S && malformed_sent < MALFORMED {
            let kind = Malformed::ALL[malformed_sent % Malformed::ALL.len()];
            tick.raw.extend(malformed_frame(kind));
            malformed_sent += 1;
        }
        for frame in tick.frames.iter_mut() {
            if t >= SEQ_JUMP_AT_S && matches!(frame.payload, Payload::Imu(_)) {
                frame.seq = frame.seq.wrapping_add(SEQ_JUMP);
            }
            if t >= CLOCK_FORWARD_AT_S {
                frame.device_time_us = frame.device_time_us.wrapping_add(CLOCK_FORWARD_US);
            }
            if t >= CLOCK_WRAP_AT_S {
                frame.device_time_us = frame.device_time_us.wrapping_add(CLOCK_WRAP_US);
            }
        }
    }
}

fn device_time_us(v: &serde_json::Value) -> u64 {
    v["header"]["origin_device_time_us"]
        .as_u64()
        .unwrap_or_else(|| panic!("no device time in {v}"))
}

#[test]
fn reordered_repeated_jumped_and_malformed_frames_are_counted_exactly() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("device_counters");
    let go = Arc::new(AtomicBool::new(false));
    // A line that waits for a starved reader: every loss counted below is one the device made.
    let device = FakeDevice::start_lossless(Scenario::Static, schedule(Arc::clone(&go)));
    // The duration only bounds a test that fails; the test stops the pipeline itself.
    let up = spawn_up(
        &ipc,
        &["--port", device.tty(), "--duration", "300", "--json"],
    );
    let beats = TopicStream::start(&ipc, "heartbeat");
    beats.wait_for("from acquisition", 0, Duration::from_secs(120), |v| {
        v["service"] == 1
    });
    drop(beats);
    let nav = TopicStream::start(&ipc, "nav");
    go.store(true, Ordering::Relaxed);
    let started_s = device.device_time_s();

    // Past the second clock jump, and a few seconds on.
    let wait_device = |s: f64| {
        let deadline = Instant::now() + Duration::from_secs(120);
        while device.device_time_s() < started_s + s {
            assert!(Instant::now() < deadline, "device stuck");
            std::thread::sleep(Duration::from_millis(50));
        }
    };
    wait_device(CLOCK_WRAP_AT_S + 0.5);
    let after_jumps = nav.len();
    wait_device(END_S);
    let since = nav.since(after_jumps);
    let all = nav.since(0);
    drop(nav);
    let summary = stop_up(&ipc, up);
    drop(device);
    // The figures for the record (`cargo test --test device_counters -- --nocapture`).
    eprintln!("{summary}");

    // Counted exactly, and nothing lost that was not.
    for (key, expected) in [
        ("malformed_frames", MALFORMED as u64),
        ("late_frames", REORDER_AT_S.len() as u64),
        ("duplicate_frames", DUPLICATE_AT_S.len() as u64),
        ("seq_jumps", 1),
        ("time_rebases", 2),
        ("lost_frames", 0),
        ("crc_errors", 0),
        // The late IMU frames are not published: no navigation output for them.
        ("dropped", REORDER_AT_S.len() as u64),
        ("restarts", 0),
    ] {
        assert_eq!(summary[key], expected, "{key}: {summary}");
    }

    // The navigation output keeps navigating after the clock jumps, its device time advancing by
    // the receive clock: 1 ms per sample at 1 kHz, never 0, never the 600 s jump.
    assert!(
        since.len() > 2_000,
        "{} samples after the jumps",
        since.len()
    );
    assert!(since.iter().all(|v| v["mode"] == 1), "not navigating");
    // Nothing to doubt after a re-based clock: integrity ok throughout, and the magnetometer still
    // updating (its aiding bit earned by accepted updates, not left over).
    if let Some(v) = since.iter().find(|v| v["integrity"] != 0) {
        panic!("integrity not ok after the clock jumps: {v}");
    }
    let mag_accepted = |v: &serde_json::Value| v["aiding_accepted"][1].as_u64().unwrap_or(0);
    let (first, last) = (&since[0], &since[since.len() - 1]);
    assert!(mag_accepted(last) > mag_accepted(first), "{first}\n{last}");
    assert!(
        last["aiding"].as_u64().unwrap_or(0) & u64::from(ipc_types::aiding::MAG) != 0,
        "{last}"
    );
    let times: Vec<u64> = all.iter().map(device_time_us).collect();
    if let Some(k) = times.windows(2).position(|w| w[1] <= w[0]) {
        panic!(
            "device time not increasing at sample {k}:\n{}\n{}",
            all[k],
            all[k + 1]
        );
    }
    let largest_step = times.windows(2).map(|w| w[1] - w[0]).max().unwrap_or(0);
    assert!(largest_step < 100_000, "a step of {largest_step} µs");
    let after: Vec<u64> = since.iter().map(device_time_us).collect();
    let span_s = (after[after.len() - 1] - after[0]) as f64 * 1e-6;
    let expected_s = (after.len() - 1) as f64 * 1e-3;
    assert!(
        (span_s - expected_s).abs() < 0.05 * expected_s,
        "device time advanced {span_s:.3} s over {} samples",
        after.len()
    );
}
