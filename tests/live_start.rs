//! An in-flight start through the running processes: a triad block's 16-bit counts of a turning,
//! accelerating vehicle, fed to a private deployment (fusion, altimeter, two navigator lanes)
//! whose navigator starts from `[navigator.start]` in the air, give the attitude the same library
//! code gives in process, sample for sample; both lanes take the configured start (neither waits
//! for the other), and nothing is left in /dev/shm. Receiver messages published on the receiver's
//! topic move the running navigators as they move the same code in process.

use ipc_types::{GnssFix, GnssFixType, Header, NavMode, NavState, PAYLOAD_VERSION, RawImu};
use rins::config::RinsConfig;
use rins::replay::input::{RawSample, ReplayInput};
use rins::replay::live::{self, LiveOptions};
use rins::replay::offline::OfflinePipeline;
use rins_navigator::attitude::quaternion_from_euler;
use rins_runtime::shutdown::Shutdown;

const RATE_HZ: f64 = 100.0;
const SAMPLES: usize = 1500;
/// Device time of sample 0, µs.
const T0_US: u64 = 1_000_000;
/// The sample at the start's own instant (`time_s = 3.0`: 3 s of device time).
const START_SAMPLE: usize = 200;

const CONFIG: &str = r#"
[device]
gyro_full_scale_dps = 100.0
accel_full_scale_g = 4.0
converter_bits = 16
imu_rate_hz = 100.0

[fusion]
rest_bias_s = 0.0

[fusion.geometry.gyro]
kind = "triad"

[fusion.geometry.accel]
kind = "triad"

[navigator]
initial_latitude_deg = 47.0
initial_longitude_deg = 8.0
initial_altitude_m = 400.0

[navigator.ekf]
initial_velocity_sigma = 5.0

[navigator.baro]
enabled = false

[navigator.mag]
enabled = false

[navigator.tilt]
enabled = true

[navigator.start]
time_s = 3.0
roll_deg = 4.0
pitch_deg = -3.0
heading_deg = 75.0
velocity_ned_mps = [6.0, 2.0, -0.5]
altitude_m = 450.0
gyro_bias_dps = [0.05, -0.02, 0.01]
"#;

/// Counts of a banking, pitching turn with a varying specific force.
fn frames() -> Vec<RawSample> {
    let g_lsb = 100f64.to_radians() / 32768.0;
    let a_lsb = 4.0 * rins_earth::STANDARD_GRAVITY / 32768.0;
    let mut seed = 0x2545_f491_u64;
    (0..SAMPLES)
        .map(|j| {
            let t = j as f64 / RATE_HZ;
            let rate = [
                0.4 * (0.9 * t).sin(),
                0.25 * (0.6 * t).cos(),
                0.15 + 0.1 * (0.3 * t).sin(),
            ];
            let force = [
                0.8 * (0.5 * t).sin(),
                -0.6 * (0.4 * t).cos(),
                -9.81 + 0.4 * (0.7 * t).sin(),
            ];
            let t_us = T0_US + j as u64 * 10_000;
            let mut frame = RawImu {
                version: PAYLOAD_VERSION,
                n_gyro: 3,
                n_accel: 3,
                valid_mask: 0b111 | (0b111 << 16),
                header: Header {
                    origin_seq: j as u64 + 1,
                    origin_device_time_us: t_us,
                    origin_rx_ns: t_us * 1000,
                    ..Header::default()
                },
                ..RawImu::default()
            };
            // A few counts of sensor noise (a fixed sequence): a noise-free channel would sit on
            // one count near each extremum and be taken for a stuck one.
            for k in 0..3 {
                frame.gyro_counts[k] = (rate[k] / g_lsb + noise(&mut seed)).round() as i16;
                frame.accel_counts[k] = (force[k] / a_lsb + noise(&mut seed)).round() as i16;
            }
            RawSample::Imu(frame)
        })
        .collect()
}

/// Uniform noise of ±4 counts from a linear congruential sequence.
fn noise(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6_364_136_223_846_793_005)
        .wrapping_add(1_442_695_040_888_963_407);
    ((*seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 8.0
}

fn navigating(states: &[NavState]) -> Vec<&NavState> {
    states
        .iter()
        .filter(|n| NavMode::from_u8(n.mode).is_some_and(|m| m != NavMode::Aligning))
        .collect()
}

fn angle_deg(a: [f64; 4], b: [f64; 4]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    2.0 * dot.abs().min(1.0).acos().to_degrees()
}

/// `raw` through a private deployment running `config` (two lanes); the output and the
/// deployment's /dev/shm prefix.
fn run_live(config: &str, raw: &[RawSample], tag: &str) -> (live::LiveOutput, String) {
    let dir = std::env::temp_dir().join(format!("rins-live-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("scratch directory");
    let config_file = dir.join("live.toml");
    std::fs::write(&config_file, config).expect("configuration written");
    let private = live::private_settings(tag).expect("private root");
    let prefix = private.prefix.clone();
    let options = LiveOptions {
        exe: Some(env!("CARGO_BIN_EXE_rins").into()),
        config: Some(config_file),
        lanes: 2,
        speed: None,
        private: Some(private),
        log: Some(dir.join("live.log")),
        gnss: false,
    };
    let shutdown = Shutdown::install().expect("signal handlers");
    let out = live::run(raw, &options, &shutdown, &mut |_, _| {});
    let log = std::fs::read_to_string(dir.join("live.log")).unwrap_or_default();
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.unwrap_or_else(|e| panic!("live run: {e:#}\n{log}")),
        prefix,
    )
}

fn assert_nothing_left(prefix: &str) {
    let leftovers: Vec<String> = std::fs::read_dir("/dev/shm")
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with(prefix))
                .collect()
        })
        .unwrap_or_default();
    assert!(leftovers.is_empty(), "left in /dev/shm: {leftovers:?}");
}

fn offline(config: &str, raw: &[RawSample]) -> [Vec<NavState>; 2] {
    let cfg = RinsConfig::parse(config, "test").expect("the configuration is valid");
    let input = ReplayInput {
        raw: raw.to_vec(),
        ..ReplayInput::default()
    };
    let built = cfg.build_services().expect("services");
    OfflinePipeline::new(built.fuser, built.altimeter, built.navigator, 2).run(&input, |_| {})
}

#[test]
fn an_in_flight_start_runs_live_as_in_process() {
    let raw = frames();
    let offline = offline(CONFIG, &raw);
    let (out, prefix) = run_live(CONFIG, &raw, "ls");

    // The state is taken at the start's own instant, published for that sample and every one
    // after it.
    let start_seq = START_SAMPLE as u64 + 1;
    for (lane, (live, off)) in out.nav.iter().zip(&offline).enumerate() {
        let (live, off) = (navigating(live), navigating(off));
        assert_eq!(
            live.len(),
            SAMPLES - START_SAMPLE,
            "lane {lane}: navigating samples"
        );
        assert_eq!(off.len(), live.len(), "lane {lane}");
        assert_eq!(live[0].header.origin_seq, start_seq, "lane {lane}");
        // The first output is the configured state itself.
        let q = quaternion_from_euler(4f64.to_radians(), (-3f64).to_radians(), 75f64.to_radians());
        let start = [q.w, q.i, q.j, q.k];
        assert!(angle_deg(live[0].quaternion, start) < 1e-9, "lane {lane}");
        assert!((live[0].altitude_m - 450.0).abs() < 1e-9);
        // Every sample after it: the processes as the library in process. The inputs are the
        // same counts and the code the same, so only float noise may differ; 1e-3° is the
        // evaluation's bound.
        let worst = live
            .iter()
            .zip(&off)
            .map(|(l, o)| {
                assert_eq!(l.header.origin_seq, o.header.origin_seq);
                angle_deg(l.quaternion, o.quaternion)
            })
            .fold(0.0, f64::max);
        assert!(worst <= 1e-3, "lane {lane}: {worst}° apart");
        // The run moved the attitude well away from the start: the comparison is not trivial.
        let last = live.last().expect("samples");
        assert!(angle_deg(last.quaternion, start) > 5.0);
    }
    assert!(
        out.excluded_channels.is_empty(),
        "{:?}",
        out.excluded_channels
    );
    assert_nothing_left(&prefix);
}

/// Receiver messages every 0.2 s from the start on: the position the solution without them had
/// at that time (`reference`, lane 0), moved `offset_north_m` north, and its velocity.
fn fixes(reference: &[NavState], offset_north_m: f64) -> Vec<RawSample> {
    let metres_per_rad = 6_371_000.0;
    navigating(reference)
        .into_iter()
        .filter(|n| (n.header.origin_device_time_us - T0_US).is_multiple_of(200_000))
        .enumerate()
        .map(|(k, n)| {
            let t_us = n.header.origin_device_time_us;
            RawSample::Gnss(GnssFix {
                fix_type: GnssFixType::Fix3d as u8,
                velocity_valid: 1,
                accuracy_reported: 1,
                header: Header {
                    origin_seq: k as u64 + 1,
                    origin_device_time_us: t_us,
                    origin_rx_ns: t_us * 1000,
                    ..Header::default()
                },
                receiver_time_us: t_us,
                latitude_rad: n.latitude_rad + offset_north_m / metres_per_rad,
                longitude_rad: n.longitude_rad,
                altitude_m: n.altitude_m,
                velocity_ned_mps: n.velocity_ned_mps,
                horizontal_accuracy_m: 1.0,
                vertical_accuracy_m: 2.0,
                speed_accuracy_mps: 0.2,
                ..GnssFix::default()
            })
        })
        .collect()
}

fn north_of_m(a: &NavState, b: &NavState) -> f64 {
    (a.latitude_rad - b.latitude_rad) * 6_371_000.0
}

#[test]
fn receiver_messages_reach_the_running_navigators_as_in_process() {
    let config = format!("{CONFIG}\n[navigator.gnss]\nenabled = true\n");
    let imu = frames();
    let without = offline(&config, &imu);
    // Fixes 3 m north of where the solution without them goes, with its velocity: each lane
    // moves north (the jump against the velocity also turns into tilt and bias, so by more
    // than the 3 m in time; what matters here is that the messages reach the filter).
    let mut raw = imu.clone();
    raw.extend(fixes(&without[0], 3.0));
    raw.sort_by_key(|s| s.rx_ns());
    let with = offline(&config, &raw);
    for (lane, (w, wo)) in with.iter().zip(&without).enumerate() {
        let (w, wo) = (navigating(w), navigating(wo));
        let moved = north_of_m(w.last().expect("samples"), wo.last().expect("samples"));
        assert!(moved > 1.5, "lane {lane}: {moved} m");
    }
    let (out, prefix) = run_live(&config, &raw, "lg");
    for (lane, (live, off)) in out.nav.iter().zip(&with).enumerate() {
        let (live, off) = (navigating(live), navigating(off));
        assert_eq!(live.len(), off.len(), "lane {lane}");
        let worst = live
            .iter()
            .zip(&off)
            .map(|(l, o)| {
                assert_eq!(l.header.origin_seq, o.header.origin_seq);
                north_of_m(l, o).abs()
            })
            .fold(0.0, f64::max);
        assert!(worst <= 1e-6, "lane {lane}: {worst} m apart");
    }
    assert_nothing_left(&prefix);
}
