//! Flight recordings made by `rins up` from its start (`[record]`): files named by run and part in
//! one directory, a new file once one reaches its size limit, and the oldest of rins's own files
//! deleted when the directory's total would pass its limit.
//!
//! - [`config`]: the `[record]` table and where the directory is;
//! - [`naming`]: the file names, which order the recordings without trusting the clock;
//! - [`dir`]: the directory's checks, its own recordings and which of them to delete;
//! - [`rotation`]: the writer side that moves to a new file without losing a sample.

pub mod config;
pub mod dir;
pub mod naming;
pub mod rotation;
