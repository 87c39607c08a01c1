//! Where the recorded data sets are found. They are not shipped in the repository (each has its own
//! licence and they weigh hundreds of megabytes): an operator downloads them into one directory and
//! names it, and the tests that read them skip with a note when a set is absent.

use std::path::PathBuf;

/// Environment variable naming the directory that holds the recorded data sets.
pub const RECORDINGS_DIR_ENV: &str = "RINS_DATA_DIR";

/// The directory holding the recorded data sets: `$RINS_DATA_DIR` when set and not empty, else `data/`
/// at the top of the repository (ignored by version control).
pub fn recordings_dir() -> PathBuf {
    match std::env::var_os(RECORDINGS_DIR_ENV) {
        Some(dir) if !dir.is_empty() => PathBuf::from(dir),
        _ => PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../data")),
    }
}

/// The data set `name` (e.g. `quadrotor-4imu`) inside [`recordings_dir`], or `None` after printing a
/// note when it is absent: the tests on real recordings skip rather than fail where none are installed.
pub fn recording_set(name: &str) -> Option<PathBuf> {
    let dir = recordings_dir().join(name);
    if dir.is_dir() {
        Some(dir)
    } else {
        eprintln!(
            "note: {} not found (`rins data fetch {name}` downloads it, or set {RECORDINGS_DIR_ENV}); test skipped",
            dir.display()
        );
        None
    }
}
