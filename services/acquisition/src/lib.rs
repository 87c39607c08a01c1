//! Serial acquisition: the sensor block's frame protocol (pure), the conversion of frames to IPC
//! payloads (pure), and the process loop that reads the serial port and publishes raw samples.

pub mod config;
pub mod protocol;
pub mod service;
pub mod to_ipc;
