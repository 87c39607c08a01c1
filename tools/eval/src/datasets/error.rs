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
        /// The file or directory.
        path: PathBuf,
        /// What the operating system reported.
        #[source]
        source: std::io::Error,
    },
    /// A file the trial needs is not there.
    #[error("{}: missing ({what})", path.display())]
    MissingFile {
        /// Where the file was looked for.
        path: PathBuf,
        /// What the file holds, for the message.
        what: &'static str,
    },
    /// The first line is not the expected header.
    #[error("{}:1: header {found:?} is not {expected:?}", path.display())]
    Header {
        /// The file.
        path: PathBuf,
        /// The first line as read.
        found: String,
        /// The header the loader expects.
        expected: String,
    },
    /// A data line cannot be used.
    #[error("{}:{line}: {reason}", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// 1-based line number in the file.
        line: usize,
        /// What is wrong with the line.
        reason: String,
    },
    /// A file has too few data lines to be used.
    #[error("{}: {rows} data rows, need at least {min}", path.display())]
    TooShort {
        /// The file.
        path: PathBuf,
        /// Data lines it has.
        rows: usize,
        /// Data lines the loader needs.
        min: usize,
    },
    /// An operation on a loaded trial does not fit it (e.g. channel count ≠ IMU count).
    #[error("{trial}: {reason}")]
    Mismatch {
        /// The trial's name.
        trial: String,
        /// What does not fit.
        reason: String,
    },
    /// The relative rotation of two IMUs could not be estimated.
    #[error("{trial}: IMU_{imu}: {source}")]
    Installation {
        /// The trial's name.
        trial: String,
        /// The index k of the IMU (`IMU_k.csv`) whose rotation failed.
        imu: usize,
        /// Why the estimate failed.
        #[source]
        source: InstallationError,
    },
}
