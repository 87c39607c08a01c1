//! Hardware bring-up end to end: a port that is no serial device, a line that carries garbage, and
//! `rins probe` on a device and on garbage. Each must say what is wrong, not only that nothing
//! arrives.

mod common;

use std::fs::File;
use std::process::{Child, Stdio};
use std::time::Duration;

use common::device::{DeviceTick, FakeDevice};
use common::{Isolated, PipelineSlot, Scratch, stderr, stop_up_output};
use rins_sim::Scenario;

/// Bytes of garbage per device tick (1 kHz): 8000 B/s.
const GARBAGE_PER_TICK: usize = 8;

/// A device that sends only garbage at the device's pace: pseudo-random bytes with no 0xA5, so
/// not even the start of a sync word.
fn garbage_device() -> FakeDevice {
    let mut state: u32 = 0x1234_5678;
    FakeDevice::start(Scenario::Static, move |tick: DeviceTick| {
        tick.frames.clear();
        for _ in 0..GARBAGE_PER_TICK {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let byte = (state >> 24) as u8;
            tick.raw.push(if byte == 0xA5 { 0x5A } else { byte });
        }
    })
}

/// `rins up ARGS` in the background, stdout piped (the status lines, or with --json the summary
/// alone), stderr (logs, and with --json the status lines) to `log`.
fn spawn_up_logging(ipc: &Isolated, args: &[&str], log: &std::path::Path) -> Child {
    let file = File::create(log).expect("log file");
    ipc.command()
        .arg("up")
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::from(file))
        .spawn()
        .expect("cannot start rins up")
}

fn count(s: &str, what: &str) -> usize {
    s.matches(what).count()
}

#[test]
fn up_on_a_port_that_is_no_serial_device_fails_naming_it() {
    let ipc = Isolated::new("bringup_null");
    let out = ipc.run(&["up", "--port", "/dev/null", "--duration", "3"]);
    let err = stderr(&out);
    assert!(!out.status.success(), "must fail:\n{err}");
    assert!(
        err.contains("no valid frame from /dev/null in 3") && err.contains("0 bytes received"),
        "{err}"
    );
    // Acquisition said why it cannot read the device.
    assert!(err.contains("not a terminal device"), "{err}");
    assert_eq!(ipc.shm_entries(), Vec::<String>::new());
}

#[test]
fn garbage_on_the_line_shows_in_status_summary_and_one_warning() {
    let _slot = PipelineSlot::take();
    let ipc = Isolated::new("bringup_garbage");
    let scratch = Scratch::new("bringup", "garbage");
    let log = scratch.path().join("stderr.log");
    let device = garbage_device();
    let up = spawn_up_logging(
        &ipc,
        &["--port", device.tty(), "--duration", "300", "--json"],
        &log,
    );
    // Acquisition has read garbage for more than its one-second window.
    let report = ipc.status_until(Duration::from_secs(120), |r| {
        r["link"]["bytes_received"].as_u64().unwrap_or(0) > 3 * 8000
    });
    let link = &report["link"];
    assert_eq!(link["valid_frames"], 0, "{link}");
    assert!(link["discarded_bytes"].as_u64().unwrap_or(0) > 0, "{link}");
    assert_eq!(link["last_decode_error"], "no-sync", "{link}");
    assert_eq!(link["crc_errors"], 0, "{link}");
    // The table carries the same line.
    let table = ipc.run(&["status"]);
    let text = String::from_utf8_lossy(&table.stdout);
    assert!(
        text.contains("0 valid frames") && text.contains("last decode error no-sync"),
        "{text}"
    );
    // The warning is logged once, however long the garbage goes on: two more heartbeats.
    let before = link["bytes_received"].as_u64().unwrap_or(0);
    ipc.status_until(Duration::from_secs(120), |r| {
        r["link"]["bytes_received"].as_u64().unwrap_or(0) > before + 2 * 8000
    });
    let out = stop_up_output(&ipc, up);
    drop(device);
    let summary = common::last_json(&out);
    let log = std::fs::read_to_string(&log).expect("stderr log");
    assert_eq!(count(&log, "no valid frame from"), 1, "{log}");
    assert!(
        log.contains("last decode error no-sync: no sync word in")
            && log.contains("wrong baud rate or not a rins device?"),
        "{log}"
    );
    // The status line (on stderr with --json) says it only in this case.
    assert!(
        log.contains("B/s discarded (no-sync)") && log.contains("| no valid frame: "),
        "{log}"
    );
    assert_eq!(summary["valid_frames"], 0, "{summary}");
    assert_eq!(summary["last_decode_error"], "no-sync", "{summary}");
    assert!(
        summary["bytes_received"].as_u64().unwrap_or(0) > 0,
        "{summary}"
    );
}

#[test]
fn probe_reports_the_device_rates_and_garbage() {
    let ipc = Isolated::new("bringup_probe");
    let device = FakeDevice::start(Scenario::Static, |_| {});
    let out = ipc.run(&["probe", "--port", device.tty(), "--seconds", "2", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v = common::last_json(&out);
    drop(device);
    // The built-in block: IMU 1 kHz, baro 50 Hz, magnetometer 100 Hz.
    for (kind, hz) in [("imu", 1000.0), ("baro", 50.0), ("mag", 100.0)] {
        let got = v["frames"][kind]["hz"].as_f64().unwrap_or(0.0);
        assert!((got - hz).abs() <= 0.1 * hz, "{kind}: {got} Hz\n{v}");
    }
    assert_eq!(v["crc_errors"], 0, "{v}");
    assert!(
        v["verdict"]
            .as_str()
            .unwrap_or_default()
            .starts_with("rins frames at "),
        "{v}"
    );

    let garbage = garbage_device();
    let out = ipc.run(&["probe", "--port", garbage.tty(), "--seconds", "1", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v = common::last_json(&out);
    drop(garbage);
    assert_eq!(v["valid_frames"], 0, "{v}");
    assert!(v["bytes"].as_u64().unwrap_or(0) > 0, "{v}");
    assert_eq!(v["last_decode_error"], "no-sync", "{v}");
    assert!(
        v["verdict"]
            .as_str()
            .unwrap_or_default()
            .starts_with("bytes but no valid frame: wrong baud rate or protocol"),
        "{v}"
    );
    // JSON only on stdout: one line.
    assert_eq!(String::from_utf8_lossy(&out.stdout).lines().count(), 1);
}

#[test]
fn probe_names_the_port_and_the_reason_it_cannot_be_read() {
    common::fails_with(
        "bringup_probe_missing",
        &["probe", "--port", "/dev/rins-no-such-port"],
        &["/dev/rins-no-such-port", "No such file or directory"],
    );
    common::fails_with(
        "bringup_probe_null",
        &["probe", "--port", "/dev/null"],
        &["/dev/null", "not a terminal device"],
    );
    common::fails_with(
        "bringup_probe_seconds",
        &["probe", "--port", "/dev/null", "--seconds", "-1"],
        &["--seconds -1: must be > 0"],
    );
}
