//! What the tests share: the real receivers' captures in `captures/` (see its `SOURCES.md`).

// Each test file is its own crate and uses only some of these.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// Where the captures are.
pub fn captures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/captures")
}

/// A capture without its leading `#` comment lines: the receiver's bytes.
pub fn receiver_bytes(mut log: &[u8]) -> &[u8] {
    while log.first() == Some(&b'#') {
        match log.iter().position(|&x| x == b'\n') {
            Some(end) => log = &log[end + 1..],
            None => return &[],
        }
    }
    log
}

/// The receiver's bytes of the capture `name` (e.g. `ublox-lea-4t.log`).
pub fn capture(name: &str) -> Vec<u8> {
    let path = captures_dir().join(name);
    let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    receiver_bytes(&bytes).to_vec()
}
