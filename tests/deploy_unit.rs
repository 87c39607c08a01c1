//! The systemd unit is one systemd accepts as written: `systemd-analyze verify` has nothing to say
//! about it, the start limits sit in [Unit] (where systemd reads them), and nothing binds the
//! service to the sensor's device, so that unplugging the block leaves MAVLink running while
//! acquisition reconnects. The service records into its state directory through `[record]`: a
//! deployment given `$STATE_DIRECTORY` as systemd gives it, with the installed configuration's
//! `on_start = true`, records there.

mod common;

use std::process::Command;

use common::{Isolated, Scratch, TempFile, last_json, stderr};

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

#[test]
fn the_service_records_into_its_state_directory_through_record_on_start() {
    // A fixed --record file would be replaced at every restart: the unit leaves it to [record].
    let exec = section("[Service]")
        .into_iter()
        .find(|(k, _)| *k == "ExecStart")
        .expect("ExecStart");
    assert!(!exec.1.contains("--record"), "{exec:?}");
    // The configuration as deploy/README.md installs it: the built-in one, recording on start.
    let built_in = rins::config::BUILT_IN;
    assert_eq!(built_in.matches("\non_start = false").count(), 1);
    let installed = TempFile::new(
        "deploy-unit",
        "toml",
        &built_in.replace("\non_start = false", "\non_start = true"),
    );
    let scratch = Scratch::new("deploy_unit", "state");
    let state = scratch.path().join("rins");
    std::os::unix::fs::DirBuilderExt::mode(&mut std::fs::DirBuilder::new(), 0o700)
        .create(&state)
        .expect("state directory");
    let ipc = Isolated::new("state_dir");
    let out = ipc
        .command()
        .env("STATE_DIRECTORY", &state)
        .args(["up", "--config", installed.path(), "--scenario", "static"])
        .args(["--duration", "3", "--json"])
        .output()
        .expect("cannot run rins up");
    assert!(out.status.success(), "{}", stderr(&out));
    let rec = last_json(&out)["recording"].clone();
    assert_eq!(rec["file"], state.to_str().expect("utf-8"), "{rec}");
    assert_eq!(rec["error"], serde_json::Value::Null, "{rec}");
    let files: Vec<_> = std::fs::read_dir(&state)
        .expect("list")
        .map(|e| e.expect("entry").path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let name = files[0].file_name().expect("name").to_string_lossy();
    assert!(
        name.starts_with("rins-000001-0001-") && name.ends_with("Z.mcap"),
        "{name}"
    );
    let read = rins_recording::read_file(&files[0]).expect("the recording reads back");
    assert_eq!(
        read.messages.len() as u64,
        rec["samples_written"].as_u64().expect("n")
    );
    assert!(read.messages.len() > 2_000, "{}", read.messages.len());
}
