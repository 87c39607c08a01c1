//! Opening a file named from outside (a command-line argument, a configuration entry) for reading,
//! without trusting what is at the path: a FIFO would block the open or the read for ever, a
//! device such as /dev/zero would be read until memory runs out, a directory is no file at all.
//!
//! The path is opened non-blocking, the open descriptor (not the path, which could be swapped in
//! between) is inspected, and a read never takes more than one byte beyond the limit, so that a
//! file that grows after the check is caught too.

use std::fs::{File, Metadata};
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

/// Why a file could not be opened or read; every case names the path.
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    /// open(2) failed (missing, no permission, …).
    #[error("cannot open {path}: {source}")]
    Open {
        /// The path given.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// fstat(2) on the open descriptor failed.
    #[error("cannot inspect {path}: {source}")]
    Inspect {
        /// The path given.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The path is a FIFO, a device, a directory, a socket: nothing to read as a file.
    #[error("{path} is a {kind}, not a regular file")]
    NotRegular {
        /// The path given.
        path: PathBuf,
        /// What it is, in words ([`kind_of`]).
        kind: &'static str,
    },
    /// The file is larger than the caller accepts.
    #[error("{path} has {len} bytes, more than the {limit} allowed")]
    TooLarge {
        /// The path given.
        path: PathBuf,
        /// Its size when inspected.
        len: u64,
        /// The largest size accepted.
        limit: u64,
    },
    /// Reading failed.
    #[error("cannot read {path}: {source}")]
    Read {
        /// The path given.
        path: PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// The file grew past the limit while it was read.
    #[error("{path} has more than the {limit} bytes allowed")]
    Grew {
        /// The path given.
        path: PathBuf,
        /// The largest size accepted.
        limit: u64,
    },
}

/// What a file system entry is, in words for messages.
pub fn kind_of(meta: &Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_symlink() {
        "symbolic link"
    } else if t.is_dir() {
        "directory"
    } else if t.is_file() {
        "regular file"
    } else if t.is_fifo() {
        "FIFO"
    } else if t.is_socket() {
        "socket"
    } else if t.is_char_device() {
        "character device"
    } else if t.is_block_device() {
        "block device"
    } else {
        "special file"
    }
}

/// Opens the regular file at `path` for reading, refusing anything else and any file of more
/// than `limit` bytes; returns it with its length as inspected.
pub fn open_regular(path: &Path, limit: u64) -> Result<(File, u64), FileError> {
    // O_NONBLOCK: opening a FIFO for reading does not wait for a writer; O_NOCTTY: a terminal never
    // becomes our controlling terminal. Neither changes anything for a regular file.
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
        .map_err(|source| FileError::Open {
            path: path.to_path_buf(),
            source,
        })?;
    let meta = file.metadata().map_err(|source| FileError::Inspect {
        path: path.to_path_buf(),
        source,
    })?;
    if !meta.file_type().is_file() {
        return Err(FileError::NotRegular {
            path: path.to_path_buf(),
            kind: kind_of(&meta),
        });
    }
    if meta.len() > limit {
        return Err(FileError::TooLarge {
            path: path.to_path_buf(),
            len: meta.len(),
            limit,
        });
    }
    Ok((file, meta.len()))
}

/// The bytes of the regular file at `path` ([`open_regular`]), at most `limit` of them.
pub fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, FileError> {
    let (file, len) = open_regular(path, limit)?;
    // The length was checked against the limit; it is only a hint for the first allocation.
    let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
    // The size can change after the check (a file still being written): the read is bounded too.
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|source| FileError::Read {
            path: path.to_path_buf(),
            source,
        })?;
    if bytes.len() as u64 > limit {
        return Err(FileError::Grew {
            path: path.to_path_buf(),
            limit,
        });
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        rins_test_support::scratch::scratch_dir("regular-file", name)
    }

    #[test]
    fn a_regular_file_is_opened_with_its_length() {
        let dir = scratch("ok");
        let path = dir.join("f");
        std::fs::write(&path, b"12345").unwrap();
        let (_, len) = open_regular(&path, 5).unwrap();
        assert_eq!(len, 5);
        assert_eq!(read_bounded(&path, 5).unwrap(), b"12345");
        let err = read_bounded(&path, 4).unwrap_err();
        assert!(
            matches!(
                err,
                FileError::TooLarge {
                    len: 5,
                    limit: 4,
                    ..
                }
            ),
            "{err}"
        );
        assert!(
            err.to_string()
                .contains("has 5 bytes, more than the 4 allowed")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn devices_fifos_and_directories_are_refused_naming_the_path() {
        let err = open_regular(Path::new("/dev/zero"), u64::MAX).unwrap_err();
        assert_eq!(
            err.to_string(),
            "/dev/zero is a character device, not a regular file"
        );
        let dir = scratch("fifo");
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_string_lossy().as_bytes()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        // No writer: a blocking open would never return.
        let err = open_regular(&fifo, u64::MAX).unwrap_err();
        assert!(
            err.to_string()
                .ends_with("fifo is a FIFO, not a regular file"),
            "{err}"
        );
        let err = open_regular(&dir, u64::MAX).unwrap_err();
        assert!(err.to_string().contains("is a directory"), "{err}");
        let err = open_regular(&dir.join("missing"), u64::MAX).unwrap_err();
        assert!(matches!(err, FileError::Open { .. }), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
