//! The GNSS receiver's serial protocols: NMEA 0183 (GGA, RMC, GST, VTG) and u-blox UBX NAV-PVT.
//!
//! [`decode`] turns the receiver's byte stream into one [`ipc_types::GnssFix`] per receiver epoch
//! through the `nmea` and `ublox` crates; [`encode`] writes the same messages for the simulated
//! receiver.

pub mod decode;
pub mod encode;
