//! Errors of the data-set loaders: each names the file, and the line where there is one.

use std::path::PathBuf;

use thiserror::Error;

use crate::installation::InstallationError;

/// Why a data set or one of its trials could not be loaded.
#[derive(Debug, Error)]
pub enum DatasetError {
    /// A file or directory could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A file the trial needs is not there.
    #[error("{}: missing ({what})", path.display())]
    MissingFile { path: PathBuf, what: &'static str },
    /// The first line is not the expected header.
    #[error("{}:1: header {found:?} is not {expected:?}", path.display())]
    Header {
        path: PathBuf,
        found: String,
        expected: String,
    },
    /// A data line cannot be used.
    #[error("{}:{line}: {reason}", path.display())]
    Malformed {
        path: PathBuf,
        /// 1-based line number in the file.
        line: usize,
        reason: String,
    },
    /// A file has too few data lines to be used.
    #[error("{}: {rows} data rows, need at least {min}", path.display())]
    TooShort {
        path: PathBuf,
        rows: usize,
        min: usize,
    },
    /// An operation on a loaded trial does not fit it (e.g. channel count ≠ IMU count).
    #[error("{trial}: {reason}")]
    Mismatch { trial: String, reason: String },
    /// The relative rotation of two IMUs could not be estimated.
    #[error("{trial}: IMU_{imu}: {source}")]
    Installation {
        trial: String,
        imu: usize,
        #[source]
        source: InstallationError,
    },
}
