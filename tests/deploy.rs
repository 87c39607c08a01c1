//! The deployment files agree with the product: the unit's command line is one `rins up` accepts,
//! and the hardening the fault-tolerance design relies on is present.

use std::process::Command;

const UNIT: &str = include_str!("../deploy/rins.service");
const UDEV: &str = include_str!("../deploy/99-rins-sensor.rules");

fn directive(key: &str) -> Option<&'static str> {
    UNIT.lines()
        .map(str::trim)
        .find_map(|l| l.strip_prefix(key).and_then(|r| r.strip_prefix('=')))
}

#[test]
fn unit_is_hardened_and_keeps_shared_memory_with_the_watchdog() {
    for (key, value) in [
        ("User", "rins"),
        ("NoNewPrivileges", "yes"),
        ("ProtectSystem", "strict"),
        ("RemoveIPC", "no"),
        ("Restart", "on-failure"),
        ("UMask", "0077"),
        ("RuntimeDirectoryMode", "0700"),
        ("KillSignal", "SIGTERM"),
    ] {
        assert_eq!(directive(key), Some(value), "{key}");
    }
    // The iceoryx2 root lives in the private runtime directory.
    assert!(UNIT.contains("Environment=RINS_IPC_ROOT=/run/rins/"));
    assert_eq!(directive("RuntimeDirectory"), Some("rins"));
}

#[test]
fn unit_command_line_is_accepted_by_rins_up() {
    let exec = directive("ExecStart").expect("ExecStart");
    let mut words = exec.split_whitespace();
    assert_eq!(words.next(), Some("/usr/local/bin/rins"));
    let args: Vec<&str> = words.collect();
    assert_eq!(args.first(), Some(&"up"));
    // Every option the unit passes is one `rins up` knows.
    let help = Command::new(env!("CARGO_BIN_EXE_rins"))
        .args(["up", "--help"])
        .output()
        .expect("cannot run rins");
    let help = String::from_utf8_lossy(&help.stdout);
    for option in args.iter().filter(|a| a.starts_with("--")) {
        assert!(help.contains(option), "rins up has no {option}");
    }
    // The device the unit binds to is the one the udev rule creates.
    assert!(exec.contains("--port /dev/rins-sensor"));
    assert!(UDEV.contains("SYMLINK+=\"rins-sensor\""));
    assert!(UDEV.contains("TAG+=\"systemd\""));
}
