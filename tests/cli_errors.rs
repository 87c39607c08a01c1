//! Bad input from outside: configuration files and devices. Each must fail with a message that
//! names the problem, and a non-zero exit.

mod common;

use common::TempFile;

fn config_file(text: &str) -> TempFile {
    TempFile::new("config", "toml", text)
}

fn fails_with(args: &[&str], expected: &[&str]) {
    common::fails_with("cli", args, expected);
}

#[test]
fn unknown_config_key_is_rejected_by_name() {
    let f = config_file("[navigator]\nalign_seconds = 2.0\n");
    fails_with(
        &["up", "--duration", "1", "--config", f.path()],
        &["align_seconds", "unknown field"],
    );
}

#[test]
fn out_of_range_value_names_field_and_value() {
    let f = config_file("[device]\nimu_rate_hz = 0\n");
    fails_with(
        &["up", "--duration", "1", "--config", f.path()],
        &["device.imu_rate_hz = 0"],
    );
    // A key from before the rate was one key is refused with what to write instead.
    let f = config_file("[sim]\nimu_rate_hz = 500\n");
    fails_with(
        &["up", "--duration", "1", "--config", f.path()],
        &["sim.imu_rate_hz is no longer read", "device.imu_rate_hz"],
    );
    // The serial line carries 12-bit counts: a 16-bit block is for replayed recordings.
    let f = config_file("[device]\nconverter_bits = 16\n");
    fails_with(
        &["up", "--duration", "1", "--config", f.path()],
        &["device.converter_bits = 16", "12-bit"],
    );
    let f = config_file(
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

#[test]
fn soak_refuses_bad_arguments_before_starting_anything() {
    fails_with(
        &["soak", "--minutes", "1", "--faults", "kill,reboot"],
        &[
            "--faults \"kill,reboot\"",
            "\"reboot\"",
            "kill, hang, sensor, disconnect",
        ],
    );
    fails_with(&["soak", "--minutes", "0"], &["--minutes 0"]);
    fails_with(
        &[
            "soak",
            "--minutes",
            "1",
            "--min-interval",
            "3",
            "--max-interval",
            "2",
        ],
        &["--min-interval 3 / --max-interval 2"],
    );
}

/// A negative number reaches the range check, which names the option and the value, instead of
/// being taken for an unknown option.
#[test]
fn negative_numbers_get_the_range_message() {
    fails_with(
        &["up", "--duration", "-5"],
        &["--duration -5: must be a positive number of seconds"],
    );
    fails_with(
        &["sim", "--duration", "-5"],
        &["--duration -5: must be a positive number of seconds"],
    );
    fails_with(&["soak", "--minutes", "-1"], &["--minutes -1"]);
}

/// A root and prefix too long together for iceoryx2's socket names: `rins up` and a tool refuse at
/// once, naming both, and nothing is created.
#[test]
fn a_root_and_prefix_too_long_for_socket_names_are_refused_naming_both() {
    let ipc = common::Isolated::new("long_names");
    let root = ipc
        .root
        .join("a-directory-name-long-enough-to-leave-no-room");
    for args in [
        &["up", "--duration", "1"][..],
        &["status", "--timeout", "1"],
    ] {
        let out = ipc
            .command()
            .args(args)
            .env("RINS_IPC_ROOT", &root)
            .output()
            .expect("cannot run rins");
        assert!(!out.status.success(), "{args:?} should fail");
        let stderr = common::stderr(&out);
        for part in [
            "RINS_IPC_ROOT",
            "RINS_IPC_PREFIX",
            "too long together",
            "at most 62",
        ] {
            assert!(
                stderr.contains(part),
                "{args:?}: {part:?} missing:\n{stderr}"
            );
        }
        assert!(!ipc.root.exists(), "{args:?} created the root");
        assert_eq!(ipc.shm_entries(), Vec::<String>::new());
    }
}

#[test]
fn a_fault_for_a_source_that_is_not_fitted_is_refused_at_start() {
    fails_with(
        &["up", "--duration", "1", "--inject", "gnss:jump=50@5s"],
        &["gnss:jump=50@5s", "no GNSS receiver is fitted", "--gnss"],
    );
    fails_with(
        &["up", "--duration", "1", "--inject", "gyro4:dead@1s"],
        &["gyro4", "4 gyro channels"],
    );
}
