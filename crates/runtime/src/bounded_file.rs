//! Reading a small text file given on the command line (`--config`, `--faults`) without trusting
//! what is at the path: a FIFO would block the open or the read for ever, a device such as
//! /dev/zero would be read until memory runs out, a directory is no file at all. The checks are
//! [`rins_regular_file`]'s, which recordings get too.

use std::path::Path;

use anyhow::{Result, anyhow};
use rins_regular_file::FileError;

/// Largest file [`read_text`] accepts by default: far above any configuration rins has, far below
/// anything that strains memory.
pub const DEFAULT_LIMIT: u64 = 1 << 20;

/// The text of the regular file at `path`, at most `limit` bytes. `what` names the file in errors
/// (e.g. "configuration file"), which also name the path and what was found there.
pub fn read_text(path: &Path, what: &str, limit: u64) -> Result<String> {
    let shown = path.display();
    let bytes = rins_regular_file::read_bounded(path, limit).map_err(|e| match e {
        FileError::Open { source, .. } | FileError::Read { source, .. } => {
            anyhow!("cannot read {what} {shown}: {source}")
        }
        FileError::Inspect { source, .. } => anyhow!("cannot inspect {what} {shown}: {source}"),
        // These name the path themselves.
        other @ (FileError::NotRegular { .. }
        | FileError::TooLarge { .. }
        | FileError::Grew { .. }) => anyhow!("{what} {other}"),
    })?;
    String::from_utf8(bytes).map_err(|e| anyhow!("{what} {shown} is not UTF-8 text: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        rins_test_support::scratch::scratch_dir("bounded-file", name)
    }

    fn error(path: &Path, limit: u64) -> String {
        format!(
            "{:#}",
            read_text(path, "configuration file", limit).unwrap_err()
        )
    }

    #[test]
    fn a_small_regular_file_is_read() {
        let dir = scratch("ok");
        let path = dir.join("a.toml");
        std::fs::write(&path, "x = 1\n").unwrap();
        assert_eq!(read_text(&path, "f", 6).unwrap(), "x = 1\n");
        let msg = error(&path, 5);
        assert!(
            msg.contains("6 bytes") && msg.contains("5 allowed"),
            "{msg}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn devices_fifos_and_directories_are_refused_at_once() {
        let msg = error(Path::new("/dev/zero"), DEFAULT_LIMIT);
        assert!(
            msg.contains("/dev/zero is a character device, not a regular file"),
            "{msg}"
        );
        let dir = scratch("fifo");
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        // No writer: a blocking open would never return.
        let msg = error(&fifo, DEFAULT_LIMIT);
        assert!(msg.contains("is a FIFO, not a regular file"), "{msg}");
        let msg = error(&dir, DEFAULT_LIMIT);
        assert!(msg.contains("is a directory"), "{msg}");
        let msg = error(&dir.join("missing"), DEFAULT_LIMIT);
        assert!(msg.contains("cannot read configuration file") && msg.contains("missing"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn binary_content_is_refused_naming_the_file() {
        let dir = scratch("binary");
        let path = dir.join("b");
        std::fs::write(&path, [0xff, 0xfe]).unwrap();
        assert!(error(&path, 10).contains("not UTF-8"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
