//! GNSS receiver acquisition: the `[gnss]` configuration, the counters the heartbeat carries, and
//! the process loop that reads the receiver's serial line, decodes it with
//! `rins-gnss-protocol` and publishes one [`ipc_types::GnssFix`] per receiver epoch.

pub mod config;
pub mod counters;
pub mod link_report;
pub mod service;
