//! Receiver epochs written as a receiver writes them, for the simulated receiver: NMEA 0183 GGA,
//! RMC, GST and VTG, or a u-blox UBX NAV-PVT frame, from the same [`ipc_types::GnssFix`] the
//! decoder produces (its `receiver_time_us` giving the UTC time of day and the GPS time of week).
//! Each writer appends to a buffer the caller reuses, so an epoch costs no allocation once the
//! buffer has grown.

mod nmea_writer;
mod ubx_writer;

pub use nmea_writer::write_nmea_epoch;
pub use ubx_writer::{write_nav_pvt, write_ubx_frame};

/// The fix type of `fix`, a number this build does not know read as no fix.
fn fix_type(fix: &ipc_types::GnssFix) -> ipc_types::GnssFixType {
    ipc_types::GnssFixType::from_u8(fix.fix_type).unwrap_or(ipc_types::GnssFixType::NoFix)
}
