//! No navigation jump at reconfiguration, end to end: the same simulated flight (`uav` scenario,
//! one seed) through the real pipeline, once clean and once with a gyro channel killed halfway
//! through the pull-up into the climb; matched by device time, the two attitudes must agree within
//! 0.05° over the second after fusion isolated the channel.
//!
//! Both flights navigate without barometer and magnetometer updates. With them, two flights of
//! identical frames do not give identical solutions: the navigator applies an aiding sample at the
//! IMU epoch it has reached when the sample arrives, which depends on process scheduling, and drops
//! one that arrives later than its lag limit; two clean flights then differ by up to 0.06°
//! (measured), as much as the quantity under test. Without them, fusion is a function of the frames
//! and the navigator of fusion's output, so before the kill the two flights agree to what the
//! alignment's magnetometer heading and the frames the serial line lost leave (see
//! [`PREMISE_DEG`]), and after it they differ by what the reconfiguration does. Over one second
//! the aiding would not take a step out anyway (heading σ 10°, baro on the height only). Without
//! aiding the attitude is the gyros' alone, so an accelerometer kill cannot move it: the test kills
//! a gyro.

mod common;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufRead, BufReader};
use std::process::Stdio;

use common::{Isolated, Scratch, TempFile, assert_no_loss_beyond_the_line, last_json, stderr};
use rins_test_support::signal::{Signal, send_signal};

/// Simulator seed of both flights.
const SEED: &str = "7";
/// Wall-clock length of each flight, s: the kill, the isolation and the second after it, plus the
/// start-up of six processes on a loaded machine.
const DURATION_S: &str = "22";
/// Device time of the kill, s: the `uav` profile rolls from 3 s, lifts off at 13 s and pitches up
/// into the climb over 4 s, so at 15 s the body turns at its fastest in the pull-up.
const KILL_S: f64 = 15.0;
/// Span after the isolation over which the two attitudes are compared, s.
const WINDOW_S: f64 = 1.0;
/// The requirement, °.
const LIMIT_DEG: f64 = 0.05;
/// Largest attitude difference allowed over the second before the kill, °. The fused rates of the
/// two flights are identical for identical frames; the navigators differ by (a) the heading the
/// alignment takes from the magnetometer samples its window happened to drain (one more or one
/// fewer: 0.002° at the end of the alignment, measured, decaying in flight) and (b) the frames the
/// serial line lost, each of which takes its 1 ms of fused rate noise with it
/// (σ ≈ 0.87 × 0.32 °/s ≈ 0.28 °/s → 0.0003°; `assert_no_loss_beyond_the_line` allows about 20 per
/// flight, so their random sum stays under 0.002°). Measured: 0.00006° with no frame lost, 0.003°
/// with 7 and 11 lost.
const PREMISE_DEG: f64 = 0.005;
/// Fewest matched samples in a compared window (1 kHz for one second): the comparison must cover
/// the window, not a few samples of it.
const MIN_MATCHED: usize = 900;

/// Navigation output of one flight: quaternion (w, x, y, z) and origin sequence number by device
/// time (µs), and the flight's summary.
struct Flight {
    attitude: BTreeMap<u64, (u64, [f64; 4])>,
    summary: serde_json::Value,
}

/// Flies the `uav` scenario with `extra` arguments, recording `rins echo nav --csv` alongside.
fn fly(name: &str, config: &TempFile, extra: &[&str]) -> Flight {
    let ipc = Isolated::new(name);
    let scratch = Scratch::new("reconfig", name);
    let csv_path = scratch.path().join("nav.csv");
    let csv = File::create(&csv_path).expect("cannot create the nav record");
    let echo = ipc
        .command()
        .args(["echo", "nav", "--csv", "--raw", "--timeout", "0"])
        .stdout(csv)
        .stderr(Stdio::null())
        .spawn()
        .expect("cannot start rins echo");
    let mut args = vec![
        "up",
        "--scenario",
        "uav",
        "--seed",
        SEED,
        "--duration",
        DURATION_S,
        "--json",
        "--config",
        config.path(),
    ];
    args.extend_from_slice(extra);
    let out = ipc.run(&args);
    // Our own child, not reaped yet: SIGTERM lets echo flush and leave its node cleanly.
    send_signal(u64::from(echo.id()), Signal::Terminate).expect("SIGTERM to our own echo");
    let echoed = echo.wait_with_output().expect("rins echo did not finish");
    assert!(echoed.status.success(), "rins echo: {:?}", echoed.status);
    assert!(out.status.success(), "rins up failed:\n{}", stderr(&out));
    let summary = last_json(&out);
    assert_no_loss_beyond_the_line(&summary);
    assert_eq!(
        ipc.shm_entries(),
        Vec::<String>::new(),
        "shared memory left"
    );
    Flight {
        attitude: read_attitudes(&csv_path),
        summary,
    }
}

/// Quaternion and sequence number by device time from `rins echo nav --csv`, navigating samples
/// only (an aligning one carries no attitude yet).
fn read_attitudes(path: &std::path::Path) -> BTreeMap<u64, (u64, [f64; 4])> {
    let mut lines = BufReader::new(File::open(path).expect("nav record")).lines();
    let header = lines
        .next()
        .expect("rins echo printed nothing")
        .expect("nav record is text");
    let names: Vec<&str> = header.split(',').collect();
    let column = |name: &str| {
        names
            .iter()
            .position(|n| *n == name)
            .unwrap_or_else(|| panic!("no column {name:?} in {header:?}"))
    };
    let time = column("header.origin_device_time_us");
    let seq = column("header.origin_seq");
    let mode = column("mode");
    let quaternion = [
        "quaternion.0",
        "quaternion.1",
        "quaternion.2",
        "quaternion.3",
    ]
    .map(column);
    let aligning = ipc_types::NavMode::Aligning as u8;
    let mut attitude = BTreeMap::new();
    for line in lines {
        let line = line.expect("nav record is text");
        let fields: Vec<&str> = line.split(',').collect();
        let int = |i: usize| -> u64 { fields[i].parse().expect("integer column") };
        if int(mode) == u64::from(aligning) {
            continue;
        }
        let q = quaternion.map(|i| fields[i].parse::<f64>().expect("quaternion column"));
        attitude.insert(int(time), (int(seq), q));
    }
    attitude
}

/// Angle between two attitudes given as unit quaternions, °: 2·acos(|q1·q2|).
fn angle_deg(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    (2.0 * dot.abs().min(1.0).acos()).to_degrees()
}

/// Attitude differences of the samples both flights have in `[from_s, to_s)` of device time, in
/// time order, after checking that matched samples carry the same sequence number.
fn differences(clean: &Flight, faulted: &Flight, from_s: f64, to_s: f64) -> Vec<(f64, f64)> {
    let range = (from_s * 1e6).round() as u64..(to_s * 1e6).round() as u64;
    clean
        .attitude
        .range(range)
        .filter_map(|(t, (seq, q))| {
            let (other_seq, other) = faulted.attitude.get(t)?;
            assert_eq!(
                seq, other_seq,
                "device time {t} µs has two sequence numbers"
            );
            Some((*t as f64 * 1e-6, angle_deg(q, other)))
        })
        .collect()
}

/// Largest and RMS of the differences, °.
fn max_rms(d: &[(f64, f64)]) -> (f64, f64) {
    let max = d.iter().map(|(_, a)| *a).fold(0.0, f64::max);
    let rms = (d.iter().map(|(_, a)| a * a).sum::<f64>() / d.len().max(1) as f64).sqrt();
    (max, rms)
}

#[test]
fn killing_a_gyro_in_the_climb_does_not_jump_the_attitude() {
    let config = TempFile::new(
        "reconfig",
        "toml",
        "[navigator.baro]\nenabled = false\n\n[navigator.mag]\nenabled = false\n",
    );
    let channel = "gyro2";
    let spec = format!("{channel}:dead@{KILL_S}s");
    // One flight after the other: two pipelines at once would starve each other.
    let clean = fly("clean", &config, &[]);
    let faulted = fly("faulted", &config, &["--inject", &spec]);

    let faults = faulted.summary["faults"].as_array().expect("faults array");
    assert_eq!(faults.len(), 1, "{}", faulted.summary);
    let record = &faults[0];
    assert_eq!(record["channel"], channel, "{record}");
    // Dead: the channel's samples stop, fusion excludes it as missing on the first one.
    let isolated = record["isolated_at_s"]
        .as_f64()
        .unwrap_or_else(|| panic!("{channel} was never isolated: {record}"));
    assert!(
        (KILL_S..KILL_S + 0.020).contains(&isolated),
        "{channel} isolated at {isolated} s: {record}"
    );

    let before = differences(&clean, &faulted, KILL_S - 1.0, KILL_S);
    assert!(
        before.len() >= MIN_MATCHED,
        "{} samples in the second before the kill",
        before.len()
    );
    let (premise, _) = max_rms(&before);
    let after = differences(&clean, &faulted, isolated, isolated + WINDOW_S);
    assert!(
        after.len() >= MIN_MATCHED,
        "{} samples in the second after the isolation at {isolated} s (flight too short?)",
        after.len()
    );
    let (max, rms) = max_rms(&after);
    let first_10_ms = after
        .iter()
        .filter(|(t, _)| *t < isolated + 0.010)
        .map(|(_, a)| *a)
        .fold(0.0, f64::max);
    eprintln!(
        "{channel} dead at {KILL_S} s, isolated at {isolated} s: before the kill max {premise:.5}°; \
         second after the isolation max {max:.4}°, RMS {rms:.4}°, first 10 ms max {first_10_ms:.5}° \
         ({} matched samples)",
        after.len()
    );
    assert!(
        premise <= PREMISE_DEG,
        "the flights differ by {premise:.5}° before the kill (> {PREMISE_DEG}°)"
    );
    assert!(
        max <= LIMIT_DEG,
        "attitude jump {max:.4}° over the second after the isolation (> {LIMIT_DEG}°)"
    );
}
