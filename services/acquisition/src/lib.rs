//! Serial acquisition: the origin header of each decoded frame's IPC payload (pure; the payload is
//! the frame type's own, from `rins-protocol`), the resume point's file, and the process loop that
//! reads the serial port, decodes it with `rins-protocol` and publishes raw samples.

pub mod config;
pub mod line_watch;
pub mod listen;
pub mod resume_file;
pub mod resume_saver;
pub mod service;
pub mod to_ipc;
