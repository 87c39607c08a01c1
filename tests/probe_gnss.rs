//! `rins probe --gnss` on a pseudo-terminal that carries a real receiver's capture, and one that
//! carries noise: the report must show the receiver's epochs, line ends and last fix, and name a
//! silent line as such.

use std::io::Write;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

use serde_json::Value;
use serialport::{SerialPort, TTYPort};

/// How long the probe listens, s; the bytes are written within its first half.
const LISTEN_S: &str = "2";
/// Bytes per write, as a serial line delivers them.
const CHUNK_BYTES: usize = 64;
/// Time to write all of a capture in: well inside the listen.
const PLAY_S: f64 = 0.8;

fn captures_dir() -> &'static Path {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/gnss-protocol/tests/captures"
    ))
}

/// Whether process `pid` holds `tty` open: the probe has opened the port and cleared its input,
/// so what is written from now on is what it reads.
fn holds_open(pid: u32, tty: &str) -> bool {
    let Ok(fds) = std::fs::read_dir(format!("/proc/{pid}/fd")) else {
        return false;
    };
    fds.flatten()
        .any(|fd| std::fs::read_link(fd.path()).is_ok_and(|target| target == Path::new(tty)))
}

/// Runs `rins probe --gnss --json` on a fresh pseudo-terminal, writes `bytes` into it at a steady
/// pace from a thread once the probe has opened it, and returns the probe's JSON report.
fn probe(bytes: Vec<u8>) -> Value {
    let (mut master, slave) = TTYPort::pair().expect("pseudo-terminal");
    let tty = slave.name().expect("pseudo-terminal name");
    let child: Child = Command::new(env!("CARGO_BIN_EXE_rins"))
        .args([
            "probe",
            "--port",
            &tty,
            "--gnss",
            "--seconds",
            LISTEN_S,
            "--json",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start rins probe");
    let deadline = Instant::now() + Duration::from_secs(20);
    while !holds_open(child.id(), &tty) {
        assert!(Instant::now() < deadline, "the probe never opened {tty}");
        thread::sleep(Duration::from_millis(5));
    }
    // The probe clears the input right after opening.
    thread::sleep(Duration::from_millis(100));
    let writer = thread::spawn(move || {
        let pause = Duration::from_secs_f64(PLAY_S * CHUNK_BYTES as f64 / bytes.len() as f64);
        for chunk in bytes.chunks(CHUNK_BYTES) {
            master
                .write_all(chunk)
                .expect("write to the pseudo-terminal");
            thread::sleep(pause);
        }
        master
    });
    let out = child.wait_with_output().expect("rins probe");
    // The master end stays open until the probe is done: a hang-up would end its listen early.
    let master = writer.join().expect("writer thread");
    drop((master, slave));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "rins probe failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(stdout.lines().count(), 1, "JSON only on stdout: {stdout}");
    serde_json::from_str(stdout.trim()).expect("probe's JSON")
}

/// The receiver's bytes of capture `name` (what follows the leading `#` comment lines) and the
/// latitude of gpsd's last fix in its `.chk` decode (the last TPV report with a position), deg.
fn capture(name: &str) -> (Vec<u8>, f64) {
    let log = std::fs::read(captures_dir().join(name)).expect("capture");
    let mut bytes = log.as_slice();
    while bytes.first() == Some(&b'#') {
        let end = bytes
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| i + 1);
        bytes = &bytes[end..];
    }
    let chk = std::fs::read_to_string(captures_dir().join(format!("{name}.chk"))).expect("chk");
    let last_lat = chk
        .lines()
        .rev()
        .filter_map(|line| serde_json::from_str::<Value>(line.trim()).ok())
        .filter(|v| v["class"] == "TPV" && v["mode"].as_u64().unwrap_or(0) >= 2)
        .find_map(|v| v["lat"].as_f64())
        .expect("a fix in the capture's .chk");
    (bytes.to_vec(), last_lat)
}

fn verdict(v: &Value) -> &str {
    v["verdict"].as_str().unwrap_or_default()
}

#[test]
fn an_nmea_receiver_with_bare_line_feeds_shows_its_fixes() {
    let (bytes, last_lat) = capture("bu353s4.log");
    let v = probe(bytes.clone());
    assert_eq!(v["bytes"].as_u64(), Some(bytes.len() as u64), "{v}");
    // gpsd reads 25 epochs with a position from this capture; rins publishes the same 25.
    assert_eq!(v["epochs_3d"].as_u64(), Some(25), "{v}");
    assert!(v["epochs"].as_u64().unwrap_or(0) >= 25, "{v}");
    assert!(v["lines_lf"].as_u64().unwrap_or(0) > 0, "{v}");
    assert_eq!(v["lines_crlf"].as_u64(), Some(0), "{v}");
    assert_eq!(v["protocols"], serde_json::json!(["NMEA"]), "{v}");
    assert_eq!(v["counters"]["checksum_errors"].as_u64(), Some(0), "{v}");
    let lat = v["last_fix"]["latitude_deg"].as_f64().expect("last fix");
    assert!((lat - last_lat).abs() < 1e-6, "{lat} vs {last_lat}\n{v}");
    assert_eq!(v["last_fix"]["protocol"], "nmea", "{v}");
    // The receiver's own clock: one fix a second.
    let hz = v["fix_hz"].as_f64().unwrap_or(0.0);
    assert!((hz - 1.0).abs() < 0.05, "{hz}\n{v}");
    assert!(
        verdict(&v).starts_with("fixes flowing: 1.0 Hz over NMEA"),
        "{v}"
    );
}

#[test]
fn a_ubx_receiver_shows_its_fixes() {
    let (bytes, last_lat) = capture("ublox-neo-m8n.log");
    let v = probe(bytes);
    assert!(v["epochs_3d"].as_u64().unwrap_or(0) > 0, "{v}");
    assert!(
        v["counters"]["ubx_frames_used"].as_u64().unwrap_or(0) > 0,
        "{v}"
    );
    assert!(
        v["protocols"]
            .as_array()
            .is_some_and(|p| p.contains(&Value::from("UBX"))),
        "{v}"
    );
    let lat = v["last_fix"]["latitude_deg"].as_f64().expect("last fix");
    assert!((lat - last_lat).abs() < 1e-6, "{lat} vs {last_lat}\n{v}");
    assert_eq!(v["last_fix"]["protocol"], "ubx", "{v}");
    assert!(verdict(&v).starts_with("fixes flowing: "), "{v}");
    assert!(verdict(&v).contains("UBX"), "{v}");
}

#[test]
fn noise_is_named_a_silent_line() {
    let mut state: u32 = 0x2545_f491;
    let noise: Vec<u8> = (0..4000)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 24) as u8
        })
        .collect();
    let v = probe(noise);
    assert_eq!(v["bytes"].as_u64(), Some(4000), "{v}");
    assert_eq!(v["epochs"].as_u64(), Some(0), "{v}");
    assert_eq!(v["last_fix"], Value::Null, "{v}");
    assert!(
        verdict(&v).starts_with("silent line: 4000 bytes but no usable NMEA sentence or UBX frame"),
        "{v}"
    );
    assert!(verdict(&v).contains("mostly unframed bytes"), "{v}");
}
