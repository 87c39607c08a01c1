//! The systemd unit is one systemd accepts as written: `systemd-analyze verify` has nothing to say
//! about it, the start limits sit in [Unit] (where systemd reads them), and nothing binds the
//! service to the sensor's device, so that unplugging the block leaves MAVLink running while
//! acquisition reconnects.

mod common;

use std::process::Command;

const UNIT: &str = include_str!("../deploy/rins.service");
/// Where the unit expects the installed executable.
const INSTALLED: &str = "/usr/local/bin/rins";

/// The directives of `section` (`[Unit]`, `[Service]`, ...), as `(key, value)`; comments skipped.
fn section(name: &str) -> Vec<(&'static str, &'static str)> {
    let mut inside = false;
    let mut found = Vec::new();
    for line in UNIT.lines().map(str::trim) {
        if line.starts_with('[') {
            inside = line == name;
        } else if inside
            && !line.starts_with('#')
            && let Some((key, value)) = line.split_once('=')
        {
            found.push((key, value));
        }
    }
    found
}

#[test]
fn start_limits_are_in_unit_and_nothing_binds_the_service_to_the_device() {
    let unit = section("[Unit]");
    let service = section("[Service]");
    assert!(!UNIT.lines().any(|l| l.trim().starts_with("BindsTo=")));
    for key in ["StartLimitIntervalSec", "StartLimitBurst"] {
        assert!(unit.iter().any(|(k, _)| *k == key), "{key} not in [Unit]");
        assert!(
            !service.iter().any(|(k, _)| *k == key),
            "{key} in [Service], where systemd ignores it"
        );
    }
    // Ordered after the device without being stopped by its removal.
    assert!(
        unit.iter()
            .any(|&(k, v)| k == "After" && v.contains("dev-rins\\x2dsensor.device"))
    );
    // The persistent place for recordings under ProtectSystem=strict.
    assert!(service.contains(&("StateDirectory", "rins")));
    assert!(service.contains(&("StateDirectoryMode", "0700")));
}

#[test]
fn systemd_analyze_verify_has_nothing_to_say_about_the_unit() {
    let probe = Command::new("systemd-analyze").arg("--version").output();
    if !probe.is_ok_and(|o| o.status.success()) {
        eprintln!("systemd-analyze is not installed here: the unit is not verified");
        return;
    }
    // The unit as installed names /usr/local/bin/rins, absent on a build machine (verify would
    // report it): verify a copy that runs the executable just built instead.
    assert!(UNIT.contains(&format!("ExecStart={INSTALLED} ")));
    let copy = UNIT.replace(
        &format!("ExecStart={INSTALLED} "),
        &format!("ExecStart={} ", env!("CARGO_BIN_EXE_rins")),
    );
    let dir = common::Scratch::new("deploy_unit", "verify");
    let path = dir.path().join("rins.service");
    std::fs::write(&path, copy).expect("write the unit's copy");
    let out = Command::new("systemd-analyze")
        .arg("verify")
        .arg(&path)
        .output()
        .expect("cannot run systemd-analyze");
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    // Other units of the machine may draw remarks of their own; none may concern this one.
    let about_unit: Vec<&str> = said.lines().filter(|l| l.contains("rins")).collect();
    assert!(
        about_unit.is_empty(),
        "systemd-analyze verify on deploy/rins.service:\n{}",
        about_unit.join("\n")
    );
    assert!(
        out.status.success(),
        "systemd-analyze verify failed:\n{said}"
    );
}
