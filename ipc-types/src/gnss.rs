//! A GNSS receiver's navigation solution, one per receiver epoch, as the `gnss` service decoded it
//! from the receiver's serial output (NMEA 0183 or u-blox UBX).

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::{Header, PAYLOAD_VERSION};

wire_enum! {
    /// What kind of fix the receiver reports ([`GnssFix::fix_type`]).
    pub enum GnssFixType: u8 {
        /// No position: the other fields are not a measurement.
        NoFix = 0 => "no-fix",
        /// The receiver's own dead reckoning: not a satellite measurement.
        DeadReckoning = 1 => "dead-reckoning",
        /// Horizontal position only (altitude held).
        Fix2d = 2 => "2d",
        /// Three-dimensional position.
        Fix3d = 3 => "3d",
        /// Differential (SBAS or DGPS) corrected.
        Differential = 4 => "dgps",
        /// RTK with float ambiguities.
        RtkFloat = 5 => "rtk-float",
        /// RTK with fixed ambiguities.
        RtkFixed = 6 => "rtk-fixed",
    }
}

impl GnssFixType {
    /// Whether the fix measures a three-dimensional position from the satellites (a 2-D fix, a
    /// dead-reckoned one or none does not).
    pub fn is_3d(self) -> bool {
        matches!(
            self,
            Self::Fix3d | Self::Differential | Self::RtkFloat | Self::RtkFixed
        )
    }
}

wire_enum! {
    /// The receiver protocol a fix was decoded from ([`GnssFix::protocol`]).
    pub enum GnssProtocol: u8 {
        /// NMEA 0183 sentences (GGA, RMC, GST, VTG) of one epoch.
        Nmea = 0 => "nmea",
        /// u-blox UBX NAV-PVT.
        Ubx = 1 => "ubx",
    }
}

/// One receiver epoch, published by the `gnss` service on [`crate::names::GNSS`].
///
/// The receiver does not know the sensor block's clock: `header.origin_device_time_us` is 0, and
/// `header.origin_rx_ns` is when the service had the epoch's last byte (CLOCK_MONOTONIC ns). The
/// navigator places the measurement on the device time base from that receive time and the
/// receiver's configured output latency. `header.origin_seq` counts the epochs the service
/// published, from 1; the service stamps [`crate::Stage::Acquisition`].
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::GnssFix")]
pub struct GnssFix {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// [`GnssFixType`] as u8.
    pub fix_type: u8,
    /// Satellites used in the solution.
    pub satellites: u8,
    /// [`GnssProtocol`] as u8.
    pub protocol: u8,
    /// 1 when `velocity_ned_mps` and `speed_accuracy_mps` were reported, 0 when not.
    pub velocity_valid: u8,
    /// 1 when `horizontal_accuracy_m` and `vertical_accuracy_m` were reported by the receiver
    /// (UBX, or NMEA GST), 0 when they were derived from the dilution of precision.
    pub accuracy_reported: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 1],
    /// Receive time and sequence, see the type's documentation.
    pub header: Header,
    /// The receiver's time of the fix, µs: UTC time of day (NMEA) or GPS time of week (UBX iTOW).
    pub receiver_time_us: u64,
    /// Latitude, radians (WGS84).
    pub latitude_rad: f64,
    /// Longitude, radians (WGS84).
    pub longitude_rad: f64,
    /// Altitude above mean sea level, metres; NaN on a 2-D fix whose receiver gave no height
    /// (an RMC-only epoch, a u-blox NAV-SOL without NAV-POSLLH).
    pub altitude_m: f64,
    /// Velocity NED, m/s (valid when `velocity_valid`).
    pub velocity_ned_mps: [f64; 3],
    /// Horizontal position accuracy, 1σ per axis, metres.
    pub horizontal_accuracy_m: f64,
    /// Vertical position accuracy, 1σ, metres; NaN where the altitude is.
    pub vertical_accuracy_m: f64,
    /// Speed accuracy, 1σ per axis, m/s.
    pub speed_accuracy_mps: f64,
    /// Horizontal dilution of precision (0 when not reported).
    pub hdop: f64,
}

impl Default for GnssFix {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            fix_type: GnssFixType::NoFix as u8,
            satellites: 0,
            protocol: GnssProtocol::Nmea as u8,
            velocity_valid: 0,
            accuracy_reported: 0,
            _pad: [0; 1],
            header: Header::default(),
            receiver_time_us: 0,
            latitude_rad: 0.0,
            longitude_rad: 0.0,
            altitude_m: 0.0,
            velocity_ned_mps: [0.0; 3],
            horizontal_accuracy_m: 0.0,
            vertical_accuracy_m: 0.0,
            speed_accuracy_mps: 0.0,
            hdop: 0.0,
        }
    }
}
