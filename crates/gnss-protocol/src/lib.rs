//! The GNSS receiver's serial protocols: NMEA 0183 (GGA, GNS, RMC, GLL, GST, VTG) and u-blox UBX.
//!
//! [`decode`] turns the receiver's byte stream into one [`ipc_types::GnssFix`] per receiver epoch
//! (NMEA sentences read by its own strict readers, UBX frames through the `ublox` crate);
//! [`encode`] writes GGA, RMC, GST, VTG and NAV-PVT for the simulated receiver.

pub mod decode;
pub mod encode;
