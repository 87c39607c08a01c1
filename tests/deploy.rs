//! The deployment files agree with the product: the unit's command line is one `rins up` accepts,
//! the hardening the fault-tolerance design relies on is present, the IPC settings it gives are
//! ones rins accepts and no user's default collides with, and the install notes tell operators the
//! same settings.

mod common;

use std::os::unix::fs::PermissionsExt;
use std::process::Command;

const UNIT: &str = include_str!("../deploy/rins.service");
const UDEV: &str = include_str!("../deploy/99-rins-sensor.rules");
const NOTES: &str = include_str!("../deploy/README.md");

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
    assert_eq!(directive("PrivateTmp"), Some("yes"));
    // A private /dev would hide the service's /dev/shm segments from operators' tools.
    assert_eq!(directive("PrivateDevices"), None);
    assert_eq!(directive("DevicePolicy"), Some("closed"));
    // The network is the MAVLink output's UDP socket and nothing else.
    assert_eq!(
        directive("RestrictAddressFamilies"),
        Some("AF_UNIX AF_INET AF_INET6")
    );
    assert_eq!(directive("SocketBindAllow"), Some("udp"));
    assert_eq!(directive("SocketBindDeny"), Some("any"));
    assert_eq!(directive("IPAddressDeny"), Some("any"));
}

/// The value the unit gives the environment variable `key`.
fn environment(key: &str) -> Option<&'static str> {
    UNIT.lines()
        .map(str::trim)
        .filter_map(|l| l.strip_prefix("Environment="))
        .find_map(|kv| kv.strip_prefix(key).and_then(|r| r.strip_prefix('=')))
}

#[test]
fn unit_prefix_overlaps_no_users_default_prefix() {
    let prefix = environment("RINS_IPC_PREFIX").expect("the unit sets its prefix");
    // Segments are matched by name prefix: neither may start with the other.
    for uid in [0, 1, 999, 1000, 65534, u32::MAX] {
        let default = rins_runtime::ipc::default_prefix(uid);
        assert!(
            !default.starts_with(prefix) && !prefix.starts_with(&default),
            "{prefix} vs {default}"
        );
    }
}

#[test]
fn install_notes_join_with_the_units_settings() {
    let prefix = environment("RINS_IPC_PREFIX").expect("prefix");
    let root = environment("RINS_IPC_ROOT").expect("root");
    let user = directive("User").expect("user");
    assert!(NOTES.contains(&format!("RINS_IPC_PREFIX={prefix}")));
    assert!(NOTES.contains(&format!("RINS_IPC_ROOT={root}")));
    assert!(NOTES.contains(&format!("RINS_IPC_OWNER={user}")));
    assert!(NOTES.contains(&format!("runuser -u {user}")));
    for word in [
        "PrivateTmp",
        "RuntimeDirectory",
        "UMask",
        "RemoveIPC",
        "PrivateDevices",
    ] {
        assert!(
            NOTES.contains(word),
            "deploy/README.md does not explain {word}"
        );
    }
}

#[test]
fn a_runtime_directory_as_systemd_makes_it_is_accepted_and_a_readable_one_refused() {
    // RuntimeDirectory= with RuntimeDirectoryMode=0700: a directory of the service user, mode 0700.
    let ipc = common::Isolated::new("runtime_dir");
    let prefix = environment("RINS_IPC_PREFIX").expect("prefix");
    std::fs::create_dir(&ipc.root).unwrap();
    let status = |mode: u32| {
        std::fs::set_permissions(&ipc.root, std::fs::Permissions::from_mode(mode)).unwrap();
        let out = ipc
            .command()
            .env("RINS_IPC_PREFIX", format!("{}{prefix}", ipc.prefix))
            .args(["status", "--timeout", "0.3"])
            .output()
            .expect("cannot run rins");
        assert!(!out.status.success(), "no deployment runs");
        common::stderr(&out)
    };
    let accepted = status(0o700);
    assert!(accepted.contains("no health report"), "{accepted}");
    let refused = status(0o755);
    assert!(
        refused.contains(&ipc.root.display().to_string()) && refused.contains("chmod 0700"),
        "{refused}"
    );
    std::fs::set_permissions(&ipc.root, std::fs::Permissions::from_mode(0o700)).unwrap();
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
