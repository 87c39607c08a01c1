//! Recordings written and read back through the files themselves.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use ipc_types::{
    Altitude, FusedImu, Header, HealthReport, NavState, PAYLOAD_VERSION, RawImu, ServiceHealth,
    names,
};
use rins_recording::{
    ChannelId, Dropped, ReadError, RecordError, RecordOptions, Recordable, Recorder, SkipReason,
    join_writer, read_bytes, read_file, record_channel, spawn_writer,
};

/// A fresh scratch directory for one test.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("rins-recording-{}-{test}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn header(seq: u64) -> Header {
    Header {
        origin_seq: 0x0123_4567_89ab + seq,
        origin_device_time_us: 1_000_000 + seq * 1000,
        origin_rx_ns: 5_000_000_000 + seq * 1_000_000,
        stage_pub_ns: [11 + seq, 22 + seq, 33 + seq, 44 + seq],
    }
}

fn nav(seq: u64, lane: u8) -> NavState {
    let mut nav = NavState {
        mode: 2,
        lane,
        aiding: 0b1011,
        header: header(seq),
        quaternion: [0.5, -0.5, 0.25, 0.125 + seq as f64],
        velocity_ned_mps: [1.5, -2.25, 0.0625],
        latitude_rad: 0.8,
        longitude_rad: -0.1 - seq as f64 * 1e-9,
        altitude_m: 123.456,
        solution_start_seq: 77,
        integrity: 1,
        integrity_reasons: 0x201,
        ..Default::default()
    };
    for (i, c) in nav.covariance_diag.iter_mut().enumerate() {
        *c = 1e-6 * (i as f64 + 1.0);
    }
    nav.aiding_accepted = [1, 2, 3, 4, 5, 6, 7];
    nav.aiding_rejected = [9, 8, 7, 6, 5, 4, u32::MAX];
    nav.gyro_bias_rps = [1e-5, -2e-5, 3e-5];
    nav.accel_bias_mps2 = [0.01, -0.02, 0.03];
    nav
}

fn fused(seq: u64) -> FusedImu {
    let mut fused = FusedImu {
        n_gyro: 6,
        n_accel: 5,
        flags: 0x81,
        header: header(seq),
        rate_rps: [0.1, -0.2, 0.3],
        specific_force_mps2: [0.0, 0.5, -9.81],
        rate_var: [1e-8; 3],
        specific_force_var: [2e-4; 3],
        gyro_test_statistic: 3.5,
        accel_test_statistic: -0.0,
        ..Default::default()
    };
    fused.gyro_state[..6].copy_from_slice(&[0, 0, 1, 2, 0, 0]);
    fused.gyro_reason[3] = 6;
    fused
}

fn raw_imu(seq: u64) -> RawImu {
    let mut raw = RawImu {
        n_gyro: 6,
        n_accel: 6,
        n_temperature: 2,
        status: 3,
        valid_mask: 0x003f_003f,
        header: header(seq),
        temperature_c: [25.5, 26.25, 0.0, 0.0],
        ..Default::default()
    };
    for i in 0..6 {
        raw.gyro_counts[i] = -2048 + i as i16 * 700;
        raw.accel_counts[i] = 2047 - i as i16 * 3;
    }
    raw
}

fn health_report() -> HealthReport {
    let mut report = HealthReport {
        version: PAYLOAD_VERSION,
        count: 3,
        now_ns: 9_876_543_210,
        uptime_ms: 42_000,
        ..Default::default()
    };
    report.services[0] = ServiceHealth {
        service: 1,
        state: 1,
        pid: 4242,
        restarts: 2,
        heartbeat_age_ms: 120,
        output_rate_hz: 999.5,
        ..Default::default()
    };
    report.services[2].heartbeat_age_ms = u32::MAX;
    report.services[2].output_rate_hz = f32::NAN;
    report.link.heard = 1;
    report.link.crc_errors = 17;
    report.redundancy.gyro_test_statistic = 1.25;
    report.redundancy.accel_state[4] = 2;
    report.nav.integrity_reasons = 0x40;
    report
}

fn altitude(seq: u64) -> Altitude {
    Altitude {
        version: PAYLOAD_VERSION,
        valid: 1,
        header: header(seq),
        height_m: 100.0 + seq as f64,
        vertical_speed_mps: -0.5,
        height_var: 0.04,
        ..Default::default()
    }
}

/// Writes a file with nav samples on both lanes, fused, raw and a health report, and returns
/// what it wrote per topic, in order.
fn write_sample_file(path: &Path) -> Vec<(String, u64, Vec<u8>)> {
    let mut recorder = Recorder::create(path, &RecordOptions::default()).unwrap();
    let nav0 = recorder
        .channel_for::<NavState>(names::NAV_LANES[0])
        .unwrap();
    let nav1 = recorder
        .channel_for::<NavState>(names::NAV_LANES[1])
        .unwrap();
    let fused_ch = recorder.channel_for::<FusedImu>(names::FUSED_IMU).unwrap();
    let raw_ch = recorder.channel_for::<RawImu>(names::RAW_IMU).unwrap();
    let health_ch = recorder.channel_for::<HealthReport>(names::HEALTH).unwrap();
    let mut written = Vec::new();
    let mut put = |recorder: &mut Recorder, ch: ChannelId, topic: &str, t: u64, bytes: &[u8]| {
        recorder.write(ch, t, t - 100, bytes).unwrap();
        written.push((topic.to_string(), t, bytes.to_vec()));
    };
    for seq in 0..3u64 {
        let t = 1_000_000 * (seq + 1);
        put(
            &mut recorder,
            raw_ch,
            names::RAW_IMU,
            t,
            raw_imu(seq).as_bytes(),
        );
        put(
            &mut recorder,
            fused_ch,
            names::FUSED_IMU,
            t + 1,
            fused(seq).as_bytes(),
        );
        put(
            &mut recorder,
            nav0,
            names::NAV_LANES[0],
            t + 2,
            nav(seq, 0).as_bytes(),
        );
        put(
            &mut recorder,
            nav1,
            names::NAV_LANES[1],
            t + 3,
            nav(seq, 1).as_bytes(),
        );
    }
    put(
        &mut recorder,
        health_ch,
        names::HEALTH,
        9_000_000,
        health_report().as_bytes(),
    );
    let summary = recorder.finish().unwrap();
    assert_eq!(summary.samples_written, 13);
    assert_eq!(summary.samples_dropped, 0);
    assert_eq!(summary.topics.len(), 5);
    assert_eq!(summary.topics[0].written, 3);
    assert_eq!(summary.topics[4].written, 1);
    assert_eq!(summary.file_bytes, std::fs::metadata(path).unwrap().len());
    written
}

#[test]
fn every_field_survives_the_round_trip() {
    let dir = scratch("round-trip");
    let path = dir.join("run.mcap");
    let written = write_sample_file(&path);
    let recording = read_file(&path).unwrap();
    assert_eq!(recording.damage, None);
    assert_eq!(recording.skipped_count, 0);
    assert_eq!(recording.messages.len(), written.len());
    for (message, (topic, t, bytes)) in recording.messages.iter().zip(&written) {
        assert_eq!(&*message.topic, topic);
        assert_eq!(message.log_time_ns, *t);
        assert_eq!(message.publish_time_ns, t - 100);
        assert_eq!(&message.payload, bytes);
    }
    let navs: Vec<NavState> = recording
        .messages
        .iter()
        .filter(|m| m.topic.starts_with("rins/nav/state"))
        .map(|m| m.decode::<NavState>().unwrap())
        .collect();
    let expected: Vec<NavState> = (0..3).flat_map(|s| [nav(s, 0), nav(s, 1)]).collect();
    assert_eq!(navs, expected);
    let fused_back: Vec<FusedImu> = recording
        .messages
        .iter()
        .filter(|m| &*m.topic == names::FUSED_IMU)
        .map(|m| m.decode().unwrap())
        .collect();
    assert_eq!(fused_back, (0..3).map(fused).collect::<Vec<_>>());
    let raw_back: Vec<RawImu> = recording
        .messages
        .iter()
        .filter(|m| &*m.topic == names::RAW_IMU)
        .map(|m| m.decode().unwrap())
        .collect();
    assert_eq!(raw_back, (0..3).map(raw_imu).collect::<Vec<_>>());
    let last = recording.messages.last().unwrap();
    let report: HealthReport = last.decode().unwrap();
    // NaN is not equal to itself: compare the bytes, then the fields around it.
    assert_eq!(report.as_bytes(), health_report().as_bytes());
    assert_eq!(report.services[0], health_report().services[0]);
    assert_eq!(report.link, health_report().link);
    assert!(report.services[2].output_rate_hz.is_nan());
    // Decoding as another type is refused.
    assert!(last.decode::<NavState>().is_err());
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn the_writer_thread_writes_ten_thousand_samples_compressed() {
    let dir = scratch("thread");
    let path = dir.join("alt.mcap");
    let mut recorder = Recorder::create(&path, &RecordOptions::default()).unwrap();
    let ch = recorder.channel_for::<Altitude>(names::ALTITUDE).unwrap();
    let (sender, handle) = spawn_writer(recorder, 10_000).unwrap();
    for seq in 0..10_000u64 {
        sender
            .try_send_payload(ch, seq * 10_000_000, seq * 10_000_000, &altitude(seq))
            .unwrap();
    }
    drop(sender);
    let summary = join_writer(handle).unwrap();
    assert_eq!(summary.samples_written, 10_000);
    assert_eq!(summary.samples_dropped, 0);
    assert_eq!(summary.topics[0].written, 10_000);
    assert_eq!(summary.payload_bytes, 10_000 * size_of::<Altitude>() as u64);
    let file_bytes = std::fs::metadata(&path).unwrap().len();
    assert_eq!(summary.file_bytes, file_bytes);
    assert!(file_bytes > 0);
    assert!(
        file_bytes < 10_000 * size_of::<Altitude>() as u64,
        "{file_bytes} bytes"
    );
    let recording = read_file(&path).unwrap();
    assert_eq!(recording.messages.len(), 10_000);
    assert_eq!(
        recording.messages[9_999].decode::<Altitude>(),
        Ok(altitude(9_999))
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// With the writer not draining the queue (its receiver has not started), a full queue drops and
/// counts instead of blocking: one sample fits, the others are dropped.
#[test]
fn a_full_queue_drops_and_counts_without_blocking() {
    let dir = scratch("full");
    let path = dir.join("full.mcap");
    let mut recorder = Recorder::create(&path, &RecordOptions::default()).unwrap();
    let alt = recorder.channel_for::<Altitude>(names::ALTITUDE).unwrap();
    let nav_ch = recorder.channel_for::<NavState>(names::NAV_STATE).unwrap();
    let (sender, receiver) = record_channel(recorder, 1);
    assert_eq!(sender.try_send_payload(alt, 1, 1, &altitude(1)), Ok(()));
    for seq in 0..5 {
        assert_eq!(
            sender.try_send_payload(alt, 2, 2, &altitude(seq)),
            Err(Dropped::Full)
        );
    }
    assert_eq!(
        sender.try_send_payload(nav_ch, 3, 3, &nav(0, 0)),
        Err(Dropped::Full)
    );
    assert_eq!(
        sender.try_send(ChannelId(7), 3, 3, &[0; 8]),
        Err(Dropped::UnknownChannel)
    );
    assert_eq!(sender.dropped_total(), 6);
    // A sample of another type is dropped at the sender, never stopping the writer.
    assert_eq!(
        sender.try_send_payload(alt, 4, 4, &nav(1, 0)),
        Err(Dropped::WrongLength)
    );
    assert_eq!(sender.dropped_total(), 7);
    drop(sender);
    let summary = receiver.run().unwrap();
    assert_eq!(summary.samples_written, 1);
    assert_eq!(summary.samples_dropped, 7);
    assert_eq!(
        (summary.topics[0].written, summary.topics[0].dropped),
        (1, 6)
    );
    assert_eq!(
        (summary.topics[1].written, summary.topics[1].dropped),
        (0, 1)
    );
    std::fs::remove_dir_all(dir).unwrap();
}

/// A slow writer thread: whatever the timing, every sample is either written or counted as
/// dropped, and the senders never wait.
#[test]
fn a_slow_writer_loses_samples_only_as_counted_drops() {
    let dir = scratch("slow");
    let path = dir.join("slow.mcap");
    let mut recorder = Recorder::create(&path, &RecordOptions::default()).unwrap();
    let alt = recorder.channel_for::<Altitude>(names::ALTITUDE).unwrap();
    let (sender, handle) = spawn_writer(recorder, 1).unwrap();
    let mut refused = 0;
    for seq in 0..5_000 {
        if sender
            .try_send_payload(alt, seq, seq, &altitude(seq))
            .is_err()
        {
            refused += 1;
        }
    }
    drop(sender);
    let summary = join_writer(handle).unwrap();
    assert_eq!(summary.samples_written + summary.samples_dropped, 5_000);
    assert_eq!(summary.samples_dropped, refused);
    assert_eq!(
        read_file(&path).unwrap().messages.len() as u64,
        summary.samples_written
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn a_payload_of_the_wrong_size_or_type_is_refused_naming_the_topic() {
    let dir = scratch("wrong-payload");
    let path = dir.join("wrong.mcap");
    let mut recorder = Recorder::create(&path, &RecordOptions::default()).unwrap();
    let ch = recorder.channel_for::<Altitude>(names::ALTITUDE).unwrap();
    let err = recorder.write(ch, 1, 1, &[0; 3]).unwrap_err();
    assert!(matches!(err, RecordError::WrongLength { .. }), "{err}");
    assert!(err.to_string().contains(names::ALTITUDE), "{err}");
    let err = recorder.write_payload(ch, 1, 1, &nav(0, 0)).unwrap_err();
    assert!(matches!(err, RecordError::WrongType { .. }), "{err}");
    let err = recorder
        .channel_for::<NavState>(names::ALTITUDE)
        .unwrap_err();
    assert!(matches!(err, RecordError::TopicConflict { .. }), "{err}");
    assert_eq!(
        recorder.channel_for::<Altitude>(names::ALTITUDE).unwrap(),
        ch
    );
    recorder.write_payload(ch, 2, 2, &altitude(2)).unwrap();
    let summary = recorder.finish().unwrap();
    assert_eq!(summary.samples_written, 1);
    assert_eq!(read_file(&path).unwrap().messages[0].sequence, 0);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn an_existing_file_or_link_is_not_overwritten_unless_asked() {
    let dir = scratch("exists");
    let path = dir.join("taken.mcap");
    std::fs::write(&path, b"precious").unwrap();
    let err = Recorder::create(&path, &RecordOptions::default()).unwrap_err();
    assert!(matches!(err, RecordError::Exists { .. }), "{err}");
    assert!(err.to_string().contains("taken.mcap"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), b"precious");

    // A link planted at the path is neither followed nor, unless asked, replaced.
    let target = dir.join("target");
    std::fs::write(&target, b"someone else's").unwrap();
    let link = dir.join("link.mcap");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let err = Recorder::create(&link, &RecordOptions::default()).unwrap_err();
    assert!(matches!(err, RecordError::Exists { .. }), "{err}");
    let options = RecordOptions {
        overwrite: true,
        ..Default::default()
    };
    Recorder::create(&link, &options).unwrap().finish().unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), b"someone else's");
    assert!(
        !std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink()
    );

    // Overwriting a file when asked.
    Recorder::create(&path, &options).unwrap().finish().unwrap();
    assert!(read_file(&path).unwrap().messages.is_empty());

    // A directory is never removed.
    let err = Recorder::create(&dir, &options).unwrap_err();
    assert!(matches!(err, RecordError::NotAFile { .. }), "{err}");
    std::fs::remove_dir_all(dir).unwrap();
}

/// A recorder killed before it finished the file: the complete chunks are read back, the rest is
/// reported as damage; cutting anywhere never panics.
#[test]
fn a_cut_off_file_yields_its_complete_chunks() {
    let dir = scratch("truncated");
    let path = dir.join("cut.mcap");
    let options = RecordOptions {
        chunk_size: 4096,
        ..Default::default()
    };
    let mut recorder = Recorder::create(&path, &options).unwrap();
    let ch = recorder.channel_for::<NavState>(names::NAV_STATE).unwrap();
    for seq in 0..2_000 {
        recorder.write_payload(ch, seq, seq, &nav(seq, 0)).unwrap();
    }
    recorder.finish().unwrap();
    let bytes = std::fs::read(&path).unwrap();

    let half = read_bytes(&bytes[..bytes.len() / 2], "half").unwrap();
    assert!(half.damage.is_some());
    assert!(!half.messages.is_empty());
    assert!(half.messages.len() < 2_000, "{}", half.messages.len());
    for (seq, message) in half.messages.iter().enumerate() {
        assert_eq!(message.decode::<NavState>(), Ok(nav(seq as u64, 0)));
    }

    for cut in (0..bytes.len()).step_by(bytes.len() / 97) {
        match read_bytes(&bytes[..cut], "cut") {
            Ok(recording) => assert!(recording.messages.len() <= 2_000),
            Err(err) => assert!(matches!(err, ReadError::NotMcap { .. }), "{err}"),
        }
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// Writes a channel by hand, as another build (or a damaged recorder) would have.
fn write_raw_channel(path: &Path, metadata: &[(&str, &str)], messages: &[Vec<u8>]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut writer = mcap::WriteOptions::new().create(file).unwrap();
    let schema = writer
        .add_schema("rins/msg/NavState", "ros2msg", b"uint16 version\n")
        .unwrap();
    let metadata: BTreeMap<String, String> = metadata
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    let channel = writer
        .add_channel(schema, names::NAV_STATE, "cdr", &metadata)
        .unwrap();
    for (i, data) in messages.iter().enumerate() {
        let header = mcap::records::MessageHeader {
            channel_id: channel,
            sequence: i as u32,
            log_time: i as u64,
            publish_time: i as u64,
        };
        writer.write_to_known_channel(&header, data).unwrap();
    }
    writer.finish().unwrap();
}

fn cdr(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    rins_recording::cdr::encode_into(bytes, &mut out);
    out
}

#[test]
fn a_channel_of_another_payload_version_is_refused_naming_the_topic() {
    let dir = scratch("version");
    let path = dir.join("old.mcap");
    let message = cdr(nav(1, 0).as_bytes());
    let meta = [("type_name", "rins::NavState"), ("payload_version", "5")];
    write_raw_channel(&path, &meta, &[message]);
    let err = read_file(&path).unwrap_err();
    match &err {
        ReadError::VersionMismatch {
            topic,
            found,
            expected,
        } => {
            assert_eq!(topic, names::NAV_STATE);
            assert_eq!(found, "5");
            assert_eq!(*expected, PAYLOAD_VERSION);
        }
        other => panic!("unexpected {other}"),
    }
    let text = err.to_string();
    assert!(
        text.contains(names::NAV_STATE) && text.contains('5'),
        "{text}"
    );

    let meta = [("type_name", "rins::Nope"), ("payload_version", "6")];
    write_raw_channel(&dir.join("unknown.mcap"), &meta, &[]);
    // No message: the channel is never used, so nothing is refused.
    assert!(
        read_file(dir.join("unknown.mcap"))
            .unwrap()
            .messages
            .is_empty()
    );
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn damaged_messages_are_skipped_and_counted() {
    let dir = scratch("skipped");
    let path = dir.join("damaged.mcap");
    let good = cdr(nav(1, 0).as_bytes());
    let short = good[..good.len() - 1].to_vec();
    let mut not_cdr = good.clone();
    not_cdr[1] = 0;
    let mut old = nav(2, 0);
    old.version = PAYLOAD_VERSION - 1;
    let version = PAYLOAD_VERSION.to_string();
    let meta = [
        ("type_name", "rins::NavState"),
        ("payload_version", version.as_str()),
    ];
    write_raw_channel(
        &path,
        &meta,
        &[short, good.clone(), not_cdr, cdr(old.as_bytes())],
    );
    let recording = read_file(&path).unwrap();
    assert_eq!(recording.messages.len(), 1);
    assert_eq!(recording.messages[0].decode::<NavState>(), Ok(nav(1, 0)));
    assert_eq!(recording.skipped_count, 3);
    let reasons: Vec<&SkipReason> = recording.skipped.iter().map(|s| &s.reason).collect();
    assert_eq!(
        reasons,
        [
            &SkipReason::WrongLength {
                expected: good.len(),
                found: good.len() - 1
            },
            &SkipReason::NotCdr,
            &SkipReason::WrongVersion {
                found: PAYLOAD_VERSION - 1
            },
        ]
    );
    assert_eq!(recording.skipped[0].topic, names::NAV_STATE);
    std::fs::remove_dir_all(dir).unwrap();
}

#[test]
fn garbage_is_not_an_mcap_file() {
    let err = read_bytes(b"definitely not a recording", "garbage").unwrap_err();
    assert!(err.to_string().contains("garbage"), "{err}");
    let err = read_file("/nonexistent/rins.mcap").unwrap_err();
    assert!(err.to_string().contains("/nonexistent/rins.mcap"), "{err}");
}

/// The file as Foxglove's Python libraries decode it (`mcap` with `mcap-ros2-support`): run only
/// where `RINS_PYTHON` names a Python with both installed.
#[test]
fn python_reads_the_file() {
    let Some(python) = std::env::var_os("RINS_PYTHON") else {
        println!("skipped: RINS_PYTHON not set");
        return;
    };
    let dir = scratch("python");
    let path = dir.join("run.mcap");
    write_sample_file(&path);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/check_mcap.py");
    let output = std::process::Command::new(python)
        .arg(&script)
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // Shown on failure: what Python decoded.
    println!("{}", String::from_utf8_lossy(&output.stdout));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).unwrap();
    let topics = &json["topics"];
    assert_eq!(topics[names::NAV_LANES[0]]["count"], 3);
    assert_eq!(topics[names::NAV_LANES[1]]["count"], 3);
    assert_eq!(topics[names::FUSED_IMU]["count"], 3);
    assert_eq!(topics[names::RAW_IMU]["count"], 3);
    assert_eq!(topics[names::HEALTH]["count"], 1);
    for lane in 0..2u8 {
        let first = &topics[names::NAV_LANES[usize::from(lane)]]["first"];
        let expected = nav(0, lane);
        assert_eq!(first["quaternion"], serde_json::json!(expected.quaternion));
        assert_eq!(
            first["velocity_ned_mps"],
            serde_json::json!(expected.velocity_ned_mps)
        );
        assert_eq!(first["header.origin_seq"], expected.header.origin_seq);
        assert_eq!(first["mode"], expected.mode);
        assert_eq!(first["lane"], lane);
        assert_eq!(first["integrity_reasons"], expected.integrity_reasons);
        assert_eq!(
            first["aiding_rejected"],
            serde_json::json!(expected.aiding_rejected)
        );
    }
    let fused_first = &topics[names::FUSED_IMU]["first"];
    assert_eq!(
        fused_first["header.stage_pub_ns"],
        serde_json::json!([11, 22, 33, 44])
    );
    assert_eq!(fused_first["gyro_test_statistic"], 3.5);
    let raw_first = &topics[names::RAW_IMU]["first"];
    assert_eq!(
        raw_first["gyro_counts"],
        serde_json::json!(raw_imu(0).gyro_counts)
    );
    assert_eq!(
        raw_first["temperature_c"],
        serde_json::json!(raw_imu(0).temperature_c)
    );
    let health = &topics[names::HEALTH]["first"];
    assert_eq!(health["services[0].pid"], 4242);
    assert_eq!(health["link.crc_errors"], 17);
    std::fs::remove_dir_all(dir).unwrap();
}
