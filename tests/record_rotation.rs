//! Flight recordings from the start of `rins up` (`[record] on_start`): at a small size limit a
//! short run rotates into several files, each one readable on its own and within the limit, which
//! together hold every sample the summary counts as written; a later run with a small total
//! deletes the oldest of rins's own recordings first, and never a file that is not one of them
//! (another name, a link). A directory others may write to, and bad limits, are refused before
//! anything starts, naming the field and the value.

mod common;

use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

use common::{Isolated, Scratch, TempFile, fails_with, last_json, num, stderr};

/// The size limit of a file in these tests, MB (10^6 bytes).
const FILE_MB: u64 = 1;

/// A configuration recording into `dir` from the start, at the given limits.
fn config(dir: &Path, max_total_mb: u64) -> TempFile {
    TempFile::new(
        "record-rotation",
        "toml",
        &format!(
            "[record]\non_start = true\ndir = {:?}\nmax_file_mb = {FILE_MB}\nmax_total_mb = {max_total_mb}\n",
            dir.to_str().expect("utf-8 path")
        ),
    )
}

/// Runs a static deployment for `seconds` on `cfg`; its summary.
fn up(name: &str, cfg: &TempFile, seconds: &str) -> serde_json::Value {
    let ipc = Isolated::new(name);
    let out = ipc.run(&[
        "up",
        "--config",
        cfg.path(),
        "--scenario",
        "static",
        "--duration",
        seconds,
        "--json",
    ]);
    assert!(out.status.success(), "rins up: {}", stderr(&out));
    assert!(ipc.shm_entries().is_empty());
    last_json(&out)
}

/// rins's own recordings in `dir` (their names), oldest first.
fn own_files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("list the directory")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("rins-") && n.ends_with(".mcap"))
        .collect();
    names.sort();
    names
}

fn file_names(list: &serde_json::Value) -> Vec<String> {
    list.as_array()
        .unwrap_or_else(|| panic!("not a list: {list}"))
        .iter()
        .map(|f| {
            let path = PathBuf::from(f.as_str().or_else(|| f["file"].as_str()).expect("a path"));
            path.file_name()
                .expect("a name")
                .to_string_lossy()
                .into_owned()
        })
        .collect()
}

#[test]
fn a_run_rotates_into_readable_files_and_a_later_one_deletes_the_oldest_only() {
    let scratch = Scratch::new("rotation", "dir");
    let dir = scratch.path().join("flights");
    // Not ours: another name, and a link named like a recording that points outside.
    let outside = scratch.path().join("precious.mcap");
    std::fs::write(&outside, b"not a recording").expect("write");
    let cfg = config(&dir, 100);

    // 1. Rotation at 1 MB over a short run (0.3 to 0.6 MB/s at 1 kHz): several files.
    let s = up("rotation", &cfg, "10");
    let rec = &s["recording"];
    let files = file_names(&rec["files"]);
    eprintln!("first run: {} files: {files:?}", files.len());
    assert!(files.len() >= 3, "{rec}");
    assert_eq!(own_files(&dir), files, "{rec}");
    assert_eq!(rec["files_deleted"], serde_json::Value::Null, "{rec}");
    assert_eq!(rec["error"], serde_json::Value::Null, "{rec}");
    // The directory was made private.
    let mode = std::fs::metadata(&dir).expect("dir").permissions().mode() & 0o777;
    assert_eq!(mode, 0o700);
    // Every file reads back whole, none passes the limit, and together they hold every sample
    // the summary counts as written: none was lost at a switch.
    let mut in_files = 0u64;
    for (i, name) in files.iter().enumerate() {
        let path = dir.join(name);
        let bytes = std::fs::metadata(&path).expect("file").len();
        let r = rins_recording::read_file(&path)
            .unwrap_or_else(|e| panic!("{name} does not read back: {e}"));
        assert_eq!(r.skipped_count, 0, "{name}");
        let n = r.messages.len() as u64;
        eprintln!("  {name}: {bytes} bytes, {n} samples");
        assert!(bytes <= FILE_MB * 1_000_000, "{name}: {bytes} bytes");
        // All but the last were closed for their size: more than half the limit.
        if i + 1 < files.len() {
            assert!(bytes > FILE_MB * 1_000_000 / 2, "{name}: {bytes} bytes");
        }
        assert_eq!(n, rec["files"][i]["samples_written"].as_u64().expect("n"));
        in_files += n;
    }
    assert_eq!(in_files as f64, num(rec, "samples_written"), "{rec}");
    assert_eq!(num(rec, "samples_dropped"), 0.0, "{rec}");
    assert_eq!(num(rec, "samples_not_recorded"), 0.0, "{rec}");
    // Every frame of the run is there: raw IMU samples of 10 s at 1 kHz, and more.
    assert!(in_files > 10_000, "{in_files}");
    std::os::unix::fs::symlink(&outside, dir.join("rins-000000-0001-20000101T000000Z.mcap"))
        .expect("link");
    std::fs::write(dir.join("flight.mcap"), b"an operator's copy").expect("write");

    // 2. A total of 2 MB: before each new file, the oldest of rins's own recordings go, the
    // first run's before the second's, and nothing else.
    let cfg = config(&dir, 2 * FILE_MB);
    let s = up("rotation_total", &cfg, "5");
    let rec = &s["recording"];
    assert_eq!(rec["error"], serde_json::Value::Null, "{rec}");
    let second = file_names(&rec["files"]);
    let deleted = file_names(&rec["files_deleted"]);
    eprintln!("second run: {second:?}, deleted {deleted:?}");
    assert!(
        second.iter().all(|n| n.starts_with("rins-000002-")),
        "{second:?}"
    );
    let all: Vec<String> = files.iter().chain(&second).cloned().collect();
    assert!(deleted.len() >= files.len(), "{deleted:?}");
    assert_eq!(deleted, all[..deleted.len()], "not the oldest first");
    let left = own_files(&dir);
    let mut expected: Vec<String> = all[deleted.len()..].to_vec();
    expected.insert(0, "rins-000000-0001-20000101T000000Z.mcap".into());
    assert_eq!(left, expected);
    let own_bytes: u64 = all[deleted.len()..]
        .iter()
        .map(|n| std::fs::metadata(dir.join(n)).expect("file").len())
        .sum();
    assert!(
        own_bytes <= 2 * FILE_MB * 1_000_000,
        "{own_bytes} bytes left"
    );
    assert_eq!(
        std::fs::read(&outside).expect("outside"),
        b"not a recording",
        "the link's target was touched"
    );
    assert!(dir.join("flight.mcap").exists());
}

#[test]
fn an_open_directory_and_bad_limits_are_refused_before_anything_starts() {
    let scratch = Scratch::new("rotation", "refused");
    let dir = scratch.path().join("open");
    std::fs::create_dir(&dir).expect("dir");
    std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o777)).expect("mode");
    let cfg = config(&dir, 100);
    fails_with(
        "rotation_open",
        &["up", "--config", cfg.path(), "--duration", "1"],
        &[
            &format!("record.dir {}: mode 0777", dir.display()),
            "other users",
        ],
    );
    let bad = TempFile::new("record-rotation", "toml", "[record]\nmax_file_mb = 0\n");
    fails_with(
        "rotation_bad",
        &["up", "--config", bad.path(), "--duration", "1"],
        &["record.max_file_mb = 0: must be 1..=4096"],
    );
    let bad = TempFile::new("record-rotation", "toml", "[record]\nmax_total_mb = 300\n");
    fails_with(
        "rotation_bad_total",
        &["up", "--config", bad.path(), "--duration", "1"],
        &["record.max_total_mb = 300: must be 512..="],
    );
    fails_with(
        "rotation_bad_cli",
        &[
            "record",
            "--dir",
            dir.to_str().expect("utf-8"),
            "--max-file-mb",
            "10",
            "--max-total-mb",
            "15",
        ],
        &["--max-total-mb = 15: must be 20..="],
    );
    fails_with(
        "rotation_file_cli",
        &["record", "x.mcap", "--max-file-mb", "3"],
        &["--max-file-mb and --max-total-mb apply to --dir: x.mcap is one file"],
    );
}
