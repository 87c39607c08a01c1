//! Receiver epochs written as a receiver writes them, for the simulated receiver: NMEA 0183 GGA,
//! RMC, GST and VTG, or a u-blox UBX NAV-PVT frame. Each writer appends to a buffer the caller
//! reuses, so an epoch costs no allocation once the buffer has grown.

mod nmea_writer;
mod ubx_writer;

use ipc_types::GnssFixType;

pub use nmea_writer::write_nmea_epoch;
pub use ubx_writer::write_nav_pvt;

/// One receiver epoch as the simulated receiver reports it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceiverEpoch {
    /// Receiver time of the fix, µs: the UTC time of day (NMEA) and the GPS time of week (UBX
    /// iTOW) are both taken from it, modulo a day and a week.
    pub time_us: u64,
    /// Fix type; [`GnssFixType::NoFix`] writes an epoch without a position.
    pub fix: GnssFixType,
    /// Satellites used.
    pub satellites: u8,
    /// Latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Altitude above mean sea level, m.
    pub altitude_m: f64,
    /// Velocity NED, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// Horizontal σ per axis, m.
    pub horizontal_accuracy_m: f64,
    /// Vertical σ, m.
    pub vertical_accuracy_m: f64,
    /// Speed σ per axis, m/s.
    pub speed_accuracy_mps: f64,
    /// Horizontal dilution of precision.
    pub hdop: f64,
}
