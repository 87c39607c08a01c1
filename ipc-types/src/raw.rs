//! Raw samples as the sensor block sent them: what acquisition publishes for every serial frame
//! it decodes (IMU, barometer, magnetometer, auxiliary, airspeed), with the device status bits.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::{Header, MAX_CHANNELS, PAYLOAD_VERSION};

/// Up to this many module temperature sensors in the sensor block.
pub const MAX_TEMPERATURES: usize = 4;

/// Device status bits carried in [`RawImu::status`].
pub mod status {
    /// The device reports an internal error (self-test failed, bus error).
    pub const DEVICE_ERROR: u32 = 1 << 0;
    /// At least one channel is saturated in this frame.
    pub const SATURATION: u32 = 1 << 1;

    /// Every bit with its name as tools print it, in bit order.
    pub const NAMES: [(u32, &str); 2] =
        [(DEVICE_ERROR, "device-error"), (SATURATION, "saturation")];
}

/// One raw IMU frame: every gyro and accelerometer channel in 12-bit signed ADC counts, as
/// acquisition decoded it from the serial line. Fusion converts the counts to SI units.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawImu")]
pub struct RawImu {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Gyro channels fitted: entries of [`RawImu::gyro_counts`] in use (at most [`MAX_CHANNELS`]).
    pub n_gyro: u8,
    /// Accelerometer channels fitted: entries of [`RawImu::accel_counts`] in use (at most
    /// [`MAX_CHANNELS`]).
    pub n_accel: u8,
    /// Temperature sensors fitted: entries of [`RawImu::temperature_c`] in use (at most
    /// [`MAX_TEMPERATURES`]).
    pub n_temperature: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 3],
    /// Device status bits, see [`status`].
    pub status: u32,
    /// Bit i: gyro channel i valid; bit 16 + i: accel channel i valid.
    pub valid_mask: u32,
    /// Origin of the frame and publish times, see [`Header`].
    pub header: Header,
    /// Gyro channel readings, signed ADC counts (12-bit range), one per sensitive axis.
    pub gyro_counts: [i16; MAX_CHANNELS],
    /// Accelerometer channel readings, signed ADC counts (12-bit range), one per sensitive axis.
    pub accel_counts: [i16; MAX_CHANNELS],
    /// Module temperatures in degrees Celsius.
    pub temperature_c: [f32; MAX_TEMPERATURES],
}

impl Default for RawImu {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            n_gyro: 0,
            n_accel: 0,
            n_temperature: 0,
            _pad: [0; 3],
            status: 0,
            valid_mask: 0,
            header: Header::default(),
            gyro_counts: [0; MAX_CHANNELS],
            accel_counts: [0; MAX_CHANNELS],
            temperature_c: [0.0; MAX_TEMPERATURES],
        }
    }
}

/// One raw barometer sample, published by acquisition; the altimeter turns it into altitude.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawBaro")]
pub struct RawBaro {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 6],
    /// Origin of the frame and publish times, see [`Header`].
    pub header: Header,
    /// Static pressure, pascal.
    pub pressure_pa: f64,
    /// The barometer's own temperature, degrees Celsius.
    pub temperature_c: f32,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad2: u32,
}

/// One raw magnetometer sample, published by acquisition; the navigator uses it for heading.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawMag")]
pub struct RawMag {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 6],
    /// Origin of the frame and publish times, see [`Header`].
    pub header: Header,
    /// Magnetic field, body frame (FRD), microtesla, as measured (the navigator applies the
    /// hard/soft-iron calibration).
    pub field_ut: [f32; 3],
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad2: u32,
}

/// One auxiliary sample, published by acquisition: the foot-pressure sensor of a foot-mounted
/// unit.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawAux")]
pub struct RawAux {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 6],
    /// Origin of the frame and publish times, see [`Header`].
    pub header: Header,
    /// Foot-pressure (force-sensitive resistor) reading, normalised: 0 no load, 1 full scale.
    pub foot_pressure: f32,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad2: u32,
}

/// One raw airspeed sample, published by acquisition: the pitot-static differential pressure as
/// the sensor block measured it. The navigator turns it into true airspeed with the density of
/// the standard atmosphere at its altitude.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawAirspeed")]
pub struct RawAirspeed {
    /// Layout version, [`PAYLOAD_VERSION`].
    pub version: u16,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 6],
    /// Origin of the frame and publish times, see [`Header`].
    pub header: Header,
    /// Differential (total minus static) pressure, pascal, offset and noise included.
    pub diff_pressure_pa: f32,
    /// The sensor's own temperature, degrees Celsius.
    pub temperature_c: f32,
}
