//! The simulator's ground truth, against which the navigation solution is scored.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::{Header, PAYLOAD_VERSION};

/// Simulator ground truth for one IMU frame, published by the simulator on
/// [`crate::names::TRUTH`]. Same conventions as [`crate::NavState`], so the two compare field by
/// field.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::Truth")]
pub struct Truth {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 6],
    /// `origin_seq` and `origin_device_time_us` of the IMU frame this truth belongs to; no
    /// receive or publish times (the frame has not been sent yet).
    pub header: Header,
    /// True attitude quaternion body (FRD) → NED, Hamilton, scalar first.
    pub quaternion: [f64; 4],
    /// True velocity NED, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// True latitude, radians.
    pub latitude_rad: f64,
    /// True longitude, radians.
    pub longitude_rad: f64,
    /// True altitude above mean sea level, metres.
    pub altitude_m: f64,
}

impl Default for Truth {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            _pad: [0; 6],
            header: Header::default(),
            quaternion: [1.0, 0.0, 0.0, 0.0],
            velocity_ned_mps: [0.0; 3],
            latitude_rad: 0.0,
            longitude_rad: 0.0,
            altitude_m: 0.0,
        }
    }
}
