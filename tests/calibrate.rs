//! `rins calibrate mag`: samples from the simulator's own magnetometer model, with known hard and
//! soft iron, go through the command and come back as the calibration that undoes them — from a
//! file made here, and end to end from a running pipeline on the `calibrate` scenario.

mod common;

use std::process::Output;

use common::{Isolated, PipelineSlot, spawn_up_navigating, stop_up};
use rins_navigator::attitude::quaternion_from_euler;
use rins_navigator::mag_calibration::MagCalibration;
use rins_protocol::MagFrame;
use rins_sim::sensor_model::SensorModel;
use rins_sim::{SensorModelConfig, SimConfig};

const HARD_IRON_UT: [f64; 3] = [12.0, -7.0, 30.0];
/// Symmetric, so the symmetric correction the command chooses is its inverse.
const SOFT_IRON: [[f64; 3]; 3] = [[1.1, 0.05, 0.05], [0.05, 0.9, 0.05], [0.05, 0.05, 1.05]];
const SAMPLES: usize = 600;
fn mag_csv(text: &str) -> common::TempFile {
    common::TempFile::new("mag", "csv", text)
}

const AXES: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];

/// The simulator's sensor configuration, its magnetometer with the test's iron.
fn sensor_config() -> SensorModelConfig {
    SensorModelConfig {
        mag_hard_iron_ut: HARD_IRON_UT,
        mag_soft_iron: SOFT_IRON,
        ..SensorModelConfig::default()
    }
}

/// Raw readings, µT, of the simulator's magnetometer over `SAMPLES` attitudes spread evenly over
/// all orientations: roll, yaw uniform and sin(pitch) uniform (the invariant measure in ZYX
/// angles), stepped by the R₃ low-discrepancy sequence.
fn sim_readings(sim: &SimConfig) -> Vec<[f64; 3]> {
    const STEP: [f64; 3] = [
        0.819_172_513_396_164_5,
        0.671_043_606_703_789_3,
        0.549_700_477_901_970_4,
    ];
    let mut model = SensorModel::new(&sim.sensors, &sim.environment(), &AXES, &AXES, 200.0, 7)
        .expect("valid sensor model");
    let mut frame = MagFrame::default();
    (0..SAMPLES)
        .map(|i| {
            let u = STEP.map(|a| (0.5 + a * i as f64).fract());
            let roll = std::f64::consts::TAU * u[0];
            let pitch = (2.0 * u[1] - 1.0).asin();
            let yaw = std::f64::consts::TAU * u[2];
            model.mag(&quaternion_from_euler(roll, pitch, yaw), &mut frame);
            frame.field_nt.map(|nt| f64::from(nt) * 1e-3)
        })
        .collect()
}

fn plain_csv(samples: &[[f64; 3]]) -> String {
    let mut text = String::from("mx_ut,my_ut,mz_ut\n");
    for s in samples {
        text.push_str(&format!("{},{},{}\n", s[0], s[1], s[2]));
    }
    text
}

fn stdout_json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "calibrate failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

fn array<const N: usize>(v: &serde_json::Value) -> [f64; N] {
    std::array::from_fn(|i| v[i].as_f64().expect("number"))
}

fn calibration(report: &serde_json::Value) -> MagCalibration {
    let w = &report["soft_iron_correction"];
    MagCalibration {
        hard_iron_ut: array(&report["hard_iron_ut"]),
        soft_iron_correction: [array(&w[0]), array(&w[1]), array(&w[2])],
    }
}

/// The `[navigator.mag_calibration]` table of a configuration fragment.
fn fragment_calibration(text: &str) -> MagCalibration {
    let value: toml::Value = toml::from_str(text).expect("fragment is TOML");
    value["navigator"]["mag_calibration"]
        .clone()
        .try_into()
        .expect("fragment holds a MagCalibration")
}

fn norm(v: [f64; 3]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

fn inverse(a: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let cof = |r: usize, c: usize| {
        let (r1, r2, c1, c2) = ((r + 1) % 3, (r + 2) % 3, (c + 1) % 3, (c + 2) % 3);
        a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]
    };
    let det: f64 = (0..3).map(|c| a[0][c] * cof(0, c)).sum();
    std::array::from_fn(|r| std::array::from_fn(|c| cof(c, r) / det))
}

#[test]
fn sim_readings_round_trip_to_the_configured_iron() {
    let sim = SimConfig {
        sensors: sensor_config(),
        ..SimConfig::default()
    };
    let field_ut = sim.earth_field.intensity_ut;
    let sigma = sim.sensors.mag_noise_ut;
    let samples = sim_readings(&sim);
    let csv = mag_csv(&plain_csv(&samples));
    let ipc = Isolated::new("calibrate");
    let report = fit_with_field(&ipc, &csv, field_ut);
    assert_eq!(report["samples"].as_u64(), Some(SAMPLES as u64));
    let cal = calibration(&report);
    assert_undoes_the_test_iron(&cal, SAMPLES, sigma);
    for m in &samples {
        let h = norm(cal.apply(*m));
        assert!(
            (h - field_ut).abs() < 0.01 * field_ut,
            "|W (m − b)| = {h} µT for m = {m:?}"
        );
    }
    assert!(report["residual_rms_ut"].as_f64().expect("number") < 2.0 * sigma);

    // The printed fragment holds the same calibration, to its printed digits.
    let fragment = fragment_calibration(report["config"].as_str().expect("config text"));
    for (a, b) in fragment.hard_iron_ut.iter().zip(cal.hard_iron_ut) {
        assert!((a - b).abs() <= 5e-5);
    }
    let w = fragment.soft_iron_correction.iter().flatten();
    for (a, b) in w.zip(cal.soft_iron_correction.iter().flatten()) {
        assert!((a - b).abs() <= 5e-7);
    }
}

/// `rins calibrate mag FILE --field-ut F --json`, its report.
fn fit_with_field(ipc: &Isolated, csv: &common::TempFile, field_ut: f64) -> serde_json::Value {
    let field_arg = field_ut.to_string();
    stdout_json(&ipc.run(&[
        "calibrate",
        "mag",
        csv.path(),
        "--field-ut",
        &field_arg,
        "--json",
    ]))
}

/// `cal`, fitted to `samples` readings with per-axis noise `sigma` µT, undoes [`HARD_IRON_UT`] and
/// [`SOFT_IRON`].
fn assert_undoes_the_test_iron(cal: &MagCalibration, samples: usize, sigma: f64) {
    // The centre of a sphere fitted to N readings with per-axis noise σ has σ √(3/N) per axis;
    // the ellipsoid's extra parameters widen that by a small factor. Eight of those, plus the
    // 1 nT quantisation of the frame.
    let tolerance = 8.0 * sigma * (3.0 / samples as f64).sqrt() + 1e-3;
    for (got, want) in cal.hard_iron_ut.iter().zip(HARD_IRON_UT) {
        assert!(
            (got - want).abs() < tolerance,
            "hard iron {:?}, want {HARD_IRON_UT:?} within {tolerance} µT",
            cal.hard_iron_ut
        );
    }
    let expected = inverse(SOFT_IRON);
    for (got, want) in cal
        .soft_iron_correction
        .iter()
        .flatten()
        .zip(expected.iter().flatten())
    {
        assert!(
            (got - want).abs() < 0.01,
            "W = {:?}, want {expected:?}",
            cal.soft_iron_correction
        );
    }
}

/// Flattens a JSON value into `a.b.0` columns, as `rins echo --csv` does.
fn flatten(prefix: &str, value: &serde_json::Value, out: &mut Vec<(String, String)>) {
    match value {
        serde_json::Value::Object(map) => {
            for (k, v) in map {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&key, v, out);
            }
        }
        serde_json::Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                flatten(&format!("{prefix}.{i}"), v, out);
            }
        }
        other => out.push((prefix.to_string(), other.to_string())),
    }
}

/// The readings as `rins echo raw-mag --csv` prints them.
fn echo_csv(samples: &[[f64; 3]]) -> String {
    let mut text = String::new();
    for (i, s) in samples.iter().enumerate() {
        let mut raw = ipc_types::RawMag::default();
        raw.header.origin_seq = i as u64;
        raw.field_ut = s.map(|x| x as f32);
        let mut columns = Vec::new();
        flatten(
            "",
            &serde_json::to_value(raw).expect("serialisable"),
            &mut columns,
        );
        if i == 0 {
            let header: Vec<&str> = columns.iter().map(|(k, _)| k.as_str()).collect();
            text.push_str(&header.join(","));
            text.push('\n');
        }
        let row: Vec<&str> = columns.iter().map(|(_, v)| v.as_str()).collect();
        text.push_str(&row.join(","));
        text.push('\n');
    }
    text
}

#[test]
fn echo_raw_mag_csv_gives_the_same_fit_and_a_pasteable_fragment() {
    let sim = SimConfig {
        sensors: sensor_config(),
        ..SimConfig::default()
    };
    let samples = sim_readings(&sim);
    let echo = mag_csv(&echo_csv(&samples));
    let plain = mag_csv(&plain_csv(&samples));
    let ipc = Isolated::new("calibrate");
    let out = ipc.run(&["calibrate", "mag", echo.path()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains(&format!("{SAMPLES} samples")), "{text}");
    for line in ["hard iron b", "residual", "RMS", "max"] {
        assert!(text.contains(line), "summary lacks {line:?}:\n{text}");
    }
    let start = text
        .find("[navigator.mag_calibration]")
        .unwrap_or_else(|| panic!("no fragment in:\n{text}"));
    let from_echo = fragment_calibration(&text[start..]);
    let reference = calibration(&stdout_json(&ipc.run(&[
        "calibrate",
        "mag",
        plain.path(),
        "--json",
    ])));
    // The echo file carries f32 microtesla: the same fit to well within the noise.
    for (a, b) in from_echo.hard_iron_ut.iter().zip(reference.hard_iron_ut) {
        assert!((a - b).abs() < 1e-3, "{from_echo:?} vs {reference:?}");
    }
    let w = from_echo.soft_iron_correction.iter().flatten();
    for (a, b) in w.zip(reference.soft_iron_correction.iter().flatten()) {
        assert!((a - b).abs() < 1e-4, "{from_echo:?} vs {reference:?}");
    }
}

fn fails_with(args: &[&str], expected: &[&str]) {
    common::fails_with("calibrate", args, expected);
}

#[test]
fn malformed_files_are_refused_by_file_and_line() {
    let cases: [(&str, &str); 6] = [
        ("", "empty file"),
        ("a,b,c\n1,2,3\n", ":1: the header has neither field_ut.0"),
        (
            "mx_ut,my_ut,mz_ut\n1,2,3\n1,2\n",
            ":3: 2 fields, the header (line 1) has 3",
        ),
        (
            "mx_ut,my_ut,mz_ut\n1,2,3\n\n1,x,3\n",
            ":4: my_ut = \"x\": not a number",
        ),
        (
            "mx_ut,my_ut,mz_ut\n1,2,NaN\n",
            ":2: mz_ut = NaN: must be finite",
        ),
        (
            "field_ut.0,field_ut.1,field_ut.2\n1,null,3\n",
            ":2: field_ut.1 = \"null\": not a number",
        ),
    ];
    for (text, expected) in cases {
        let csv = mag_csv(text);
        let located = format!("{}{expected}", csv.path());
        let expected = if text.is_empty() { expected } else { &located };
        fails_with(&["calibrate", "mag", csv.path()], &[expected]);
    }
    fails_with(
        &["calibrate", "mag", "/nonexistent/mag.csv"],
        &["cannot read magnetometer samples /nonexistent/mag.csv"],
    );
}

#[test]
fn unusable_samples_are_refused_with_the_reason() {
    let sim = SimConfig {
        sensors: sensor_config(),
        ..SimConfig::default()
    };
    let samples = sim_readings(&sim);
    let few = mag_csv(&plain_csv(&samples[..19]));
    fails_with(
        &["calibrate", "mag", few.path()],
        &[few.path(), "19 samples: at least 20 are needed"],
    );

    // Level and turned in yaw only: the field sweeps a cone.
    let mut model = SensorModel::new(&sim.sensors, &sim.environment(), &AXES, &AXES, 200.0, 7)
        .expect("valid sensor model");
    let mut frame = MagFrame::default();
    let yaw_only: Vec<[f64; 3]> = (0..200)
        .map(|i| {
            let yaw = std::f64::consts::TAU * f64::from(i) / 200.0;
            model.mag(&quaternion_from_euler(0.0, 0.0, yaw), &mut frame);
            frame.field_nt.map(|nt| f64::from(nt) * 1e-3)
        })
        .collect();
    let flat = mag_csv(&plain_csv(&yaw_only));
    fails_with(
        &["calibrate", "mag", flat.path()],
        &["rotate the vehicle through more orientations"],
    );

    let all = mag_csv(&plain_csv(&samples));
    fails_with(
        &["calibrate", "mag", all.path(), "--field-ut", "0"],
        &["--field-ut 0: must be a positive number"],
    );
}

/// `[sim.calibration]` with the test's iron and 3 s turns: one cycle of turns lasts 34 s.
fn calibrate_scenario_config() -> String {
    let row = |r: [f64; 3]| format!("[{}, {}, {}]", r[0], r[1], r[2]);
    format!(
        "[sim.calibration]\nsweep_s = 3.0\nhard_iron_ut = {}\nsoft_iron = [{}, {}, {}]\n",
        row(HARD_IRON_UT),
        row(SOFT_IRON[0]),
        row(SOFT_IRON[1]),
        row(SOFT_IRON[2])
    )
}

/// `rins up --scenario calibrate` in one terminal, `rins echo raw-mag --csv` and `rins calibrate
/// mag` in the other: the fit recovers the iron the configuration gave the simulator.
#[test]
fn calibrate_scenario_gives_the_simulated_iron_back() {
    const MAG_SAMPLES: usize = 3500;
    let _slot = PipelineSlot::take();
    let config = common::TempFile::new("calibrate", "toml", &calibrate_scenario_config());
    let ipc = Isolated::new("calibrate_e2e");
    let up = spawn_up_navigating(
        &ipc,
        &[
            "--scenario",
            "calibrate",
            "--config",
            config.path(),
            "--duration",
            "300",
            "--json",
        ],
    );
    // 35 s at 100 Hz: a whole cycle of turns, wherever in the cycle it starts.
    let count = MAG_SAMPLES.to_string();
    let echo = ipc.run(&["echo", "raw-mag", "--csv", "--count", &count]);
    stop_up(&ipc, up);
    assert!(echo.status.success(), "{}", common::stderr(&echo));
    let csv = mag_csv(&String::from_utf8_lossy(&echo.stdout));

    let sim = SimConfig::default();
    let report = fit_with_field(&ipc, &csv, sim.earth_field.intensity_ut);
    assert_eq!(report["samples"].as_u64(), Some(MAG_SAMPLES as u64));
    // Turned through the whole sphere of directions (1/3 for a uniform sphere, 0 for a plane).
    assert!(
        report["direction_spread"].as_f64().expect("number") > 0.2,
        "{report}"
    );
    let cal = calibration(&report);
    eprintln!(
        "calibrate scenario: hard iron {:?} µT, W {:?}",
        cal.hard_iron_ut, cal.soft_iron_correction
    );
    assert_undoes_the_test_iron(&cal, MAG_SAMPLES, sim.sensors.mag_noise_ut);
}
