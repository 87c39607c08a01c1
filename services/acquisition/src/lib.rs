//! Serial acquisition: the sensor block's frame protocol (pure), the conversion of frames to IPC
//! payloads (pure), and the process loop that reads the serial port and publishes raw samples.

pub mod backoff;
pub mod config;
pub mod presence;
pub mod protocol;
pub mod resume_file;
pub mod service;
pub mod to_ipc;
