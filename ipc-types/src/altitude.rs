//! The altimeter's output: barometric height and vertical speed.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::Header;

/// Barometric altitude, published by the altimeter for every raw barometer sample; the navigator
/// uses it for height updates.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::Altitude")]
pub struct Altitude {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// 1 when the barometer sample was accepted, 0 when it was rejected (implausible or not
    /// finite): the estimate fields then repeat the last estimate, or are zero before the first.
    pub valid: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 5],
    /// The barometer sample's header, with the altimeter's publish time stamped.
    pub header: Header,
    /// Height above mean sea level (ISA with the configured QNH), metres.
    pub height_m: f64,
    /// Vertical speed, positive up, m/s.
    pub vertical_speed_mps: f64,
    /// Variance of `height_m`, m².
    pub height_var: f64,
}
