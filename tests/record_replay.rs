//! Recording and deterministic replay end to end: a 20 s uav flight with a receiver and a gyro
//! killed at 8 s is recorded from the start (`rins up --gnss --record`); the raw topics of the file, fed through a fresh
//! deployment as fast as it takes them, give the same navigation output bit for bit (both lanes,
//! every sample, all but the stages' publish times), and so does the in-process replay; a recording
//! whose navigator applied an aiding reading late (a burst after a stall) is said so, and its two
//! replays agree with each other. The file holds every topic, the injected fault as fusion saw it,
//! and decodes in Python's MCAP libraries.

mod common;

use common::python::{interpreter, run_script};
use common::{Isolated, Scratch, last_json, num, stderr};
use ipc_types::{ChannelState, FusedImu, names};

#[test]
fn a_recorded_flight_replays_to_the_same_navigation_output() {
    let scratch = Scratch::new("replay", "flight");
    let file = scratch.path().join("flight.mcap");
    let file_s = file.to_str().expect("utf-8 path");
    let recording = Isolated::new("rec");
    let up = recording.run(&[
        "up",
        "--gnss",
        "--duration",
        "20",
        "--json",
        "--inject",
        "gyro1:dead@8s",
        "--record",
        file_s,
    ]);
    assert!(up.status.success(), "rins up: {}", stderr(&up));
    assert!(recording.shm_entries().is_empty());

    // Every topic is there; fusion excluded the dead gyro.
    let rec = rins_recording::read_file(&file).expect("the recording reads back");
    assert_eq!(rec.skipped_count, 0);
    let count = |topic: &str| rec.messages.iter().filter(|m| &*m.topic == topic).count();
    let imu = count(names::RAW_IMU);
    assert!(imu > 15_000, "{imu} raw IMU frames in 20 s");
    // Each stage's output, one per frame (the last frames may have been read while the stages
    // were already stopping).
    for topic in [names::FUSED_IMU, names::NAV_LANES[0], names::NAV_LANES[1]] {
        let n = count(topic);
        assert!(
            n <= imu && n + 5 >= imu,
            "{topic}: {n} samples for {imu} frames"
        );
    }
    let nav = count(names::NAV_LANES[0]) + count(names::NAV_LANES[1]);
    for topic in [
        names::RAW_BARO,
        names::RAW_MAG,
        names::ALTITUDE,
        names::TRUTH,
        names::HEALTH,
        names::GNSS_LINK,
    ] {
        assert!(count(topic) > 0, "{topic}");
    }
    // The receiver's fixes, 5 a second once it has one, which the replays publish again.
    let fixes = count(names::GNSS);
    assert!(
        (60..=101).contains(&fixes),
        "{fixes} receiver fixes in 20 s"
    );
    let last_fused: FusedImu = rec
        .messages
        .iter()
        .rfind(|m| &*m.topic == names::FUSED_IMU)
        .expect("fused samples")
        .decode()
        .expect("decodes");
    assert_eq!(last_fused.gyro_state[1], ChannelState::Excluded as u8);

    // Live, as fast as the pipeline takes it: identical, sample for sample. Unless the recorded
    // navigator applied an aiding reading late (a burst of frames after a stall of the loaded
    // machine can bring an altitude after the IMU frames it had to precede): a replay applies it
    // in its place and cannot reproduce that, and the two replays must then agree with each
    // other instead.
    let replaying = Isolated::new("rep");
    let live_run = replaying.run_with_timeout(
        &["replay", file_s, "--as-fast-as-possible", "--json"],
        std::time::Duration::from_secs(300),
    );
    let live = last_json(&live_run);
    let recorded_late = num(&live, "recorded_late_aiding");
    let clean = recorded_late == 0.0;
    assert_eq!(
        num(&live, "nav_samples_compared"),
        2.0 * imu as f64,
        "{live}"
    );
    assert_eq!(num(&live, "nav_samples_missing"), 0.0, "{live}");
    if clean {
        assert!(live_run.status.success(), "{live}");
        assert_eq!(num(&live, "nav_samples_different"), 0.0, "{live}");
    }
    assert!(replaying.shm_entries().is_empty());

    // In process, through the same library code: identical too.
    let offline_run = Isolated::new("off").run(&["replay", file_s, "--offline", "--json"]);
    let offline = last_json(&offline_run);
    assert_eq!(num(&offline, "nav_samples_compared"), nav as f64);
    assert_eq!(num(&offline, "recorded_late_aiding"), recorded_late);
    if clean {
        assert!(offline_run.status.success(), "{offline}");
        assert_eq!(num(&offline, "nav_samples_different"), 0.0, "{offline}");
    } else {
        eprintln!(
            "the recorded navigator applied {recorded_late} aiding readings late: the replays \
             are compared with each other"
        );
        for field in ["nav_samples_different", "first_different"] {
            assert_eq!(live[field], offline[field], "{field}: {live} vs {offline}");
        }
    }

    // Foxglove's Python decoders read every message.
    if let Some(python) = interpreter("a_recorded_flight_replays_to_the_same_navigation_output") {
        let out = run_script(
            &python,
            &replaying,
            "crates/recording/tests/python/check_mcap.py",
            &[file_s],
        );
        assert!(out.status.success(), "{}", stderr(&out));
        let decoded: serde_json::Value =
            serde_json::from_slice(&out.stdout).expect("check_mcap.py prints JSON");
        let lane0 = &decoded["topics"][names::NAV_STATE];
        assert_eq!(
            lane0["count"].as_u64(),
            Some(count(names::NAV_STATE) as u64),
            "{decoded}"
        );
        assert_eq!(lane0["first"]["lane"].as_u64(), Some(0), "{decoded}");
    }
}

#[test]
fn a_replay_of_a_file_without_raw_topics_is_refused_clearly() {
    let scratch = Scratch::new("replay", "empty");
    let file = scratch.path().join("empty.mcap");
    let mut recorder =
        rins_recording::Recorder::create(&file, &rins_recording::RecordOptions::default())
            .expect("creates");
    let ch = recorder
        .channel_for::<ipc_types::NavState>(names::NAV_STATE)
        .expect("channel");
    recorder
        .write_payload(ch, 1, 1, &ipc_types::NavState::default())
        .expect("writes");
    recorder.finish().expect("finishes");
    common::fails_with(
        "replay_empty",
        &["replay", file.to_str().expect("utf-8"), "--offline"],
        &["no raw sensor samples to replay"],
    );
    common::fails_with(
        "replay_speed",
        &["replay", file.to_str().expect("utf-8"), "--speed", "-2"],
        &["--speed -2"],
    );
}
