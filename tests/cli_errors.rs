//! Bad input from outside: configuration files and devices. Each must fail with a message that
//! names the problem, and a non-zero exit.

mod common;

use std::io::Write;

use common::Isolated;

/// A configuration file that is removed when dropped.
struct ConfigFile(std::path::PathBuf);

impl ConfigFile {
    fn new(text: &str) -> Self {
        static N: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);
        let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let path =
            std::env::temp_dir().join(format!("rins-test-config-{}-{n}.toml", std::process::id()));
        std::fs::File::create(&path)
            .and_then(|mut f| f.write_all(text.as_bytes()))
            .expect("cannot write a temporary configuration file");
        Self(path)
    }

    fn path(&self) -> &str {
        self.0.to_str().expect("temporary path is UTF-8")
    }
}

impl Drop for ConfigFile {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

fn fails_with(args: &[&str], expected: &[&str]) {
    let ipc = Isolated::new("cli");
    let out = ipc.run(args);
    assert!(!out.status.success(), "{args:?} should fail");
    let stderr = String::from_utf8_lossy(&out.stderr);
    for e in expected {
        assert!(
            stderr.contains(e),
            "{args:?}: stderr lacks {e:?}:\n{stderr}"
        );
    }
}

#[test]
fn unknown_config_key_is_rejected_by_name() {
    let f = ConfigFile::new("[navigator]\nalign_seconds = 2.0\n");
    fails_with(
        &["up", "--duration", "1", "--config", f.path()],
        &["align_seconds", "unknown field"],
    );
}

#[test]
fn out_of_range_value_names_field_and_value() {
    let f = ConfigFile::new("[sim]\nimu_rate_hz = 0\n");
    fails_with(
        &["up", "--duration", "1", "--config", f.path()],
        &["sim.imu_rate_hz = 0"],
    );
    let f = ConfigFile::new(
        "[fusion.geometry.gyro]\nkind = \"pyramid\"\nn = 2\nalpha_deg = 30\nbeta0_deg = 0\n",
    );
    fails_with(
        &["service", "fusion", "--config", f.path()],
        &["fusion.geometry.gyro.n = 2"],
    );
}

#[test]
fn missing_config_file_and_missing_device_are_reported() {
    fails_with(
        &["up", "--config", "/nonexistent/rins.toml"],
        &["cannot read configuration file /nonexistent/rins.toml"],
    );
    fails_with(
        &[
            "up",
            "--port",
            "/dev/rins-no-such-device",
            "--duration",
            "1",
        ],
        &["serial device /dev/rins-no-such-device does not exist"],
    );
}

#[test]
fn unknown_topic_is_rejected() {
    fails_with(&["echo", "speed"], &["unknown topic \"speed\"", "nav"]);
}

#[test]
fn echo_without_a_pipeline_times_out_naming_the_topic() {
    fails_with(
        &["echo", "nav", "--count", "1", "--timeout", "0.3"],
        &["no sample on topic", "rins up"],
    );
    fails_with(&["echo", "nav", "--timeout=-1"], &["--timeout -1"]);
}
