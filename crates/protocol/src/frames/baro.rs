//! The barometer frame: static pressure and sensor temperature.

use ipc_types::{Header, PAYLOAD_VERSION, RawBaro, names};

use super::SensorFrame;
use crate::error::DecodeError;
use crate::frame_type::FrameType;
use crate::wire::{Reader, Writer};

/// Barometer payload: f32 pressure + i16 temperature.
pub const BARO_PAYLOAD_LEN: usize = 6;

/// Barometer frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaroFrame {
    /// Static pressure, pascal.
    pub pressure_pa: f32,
    /// Sensor temperature, hundredths of a degree Celsius.
    pub temperature_centi_c: i16,
}

impl SensorFrame for BaroFrame {
    const TYPE: FrameType = FrameType::Baro;
    const MAX_PAYLOAD_LEN: usize = BARO_PAYLOAD_LEN;
    type Ipc = RawBaro;
    const TOPIC: &'static str = names::RAW_BARO;

    fn encode(&self, w: &mut Writer<'_>) {
        w.f32(self.pressure_pa);
        w.i16(self.temperature_centi_c);
    }

    fn decode(payload: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Reader::payload(Self::TYPE, payload);
        Ok(Self {
            pressure_pa: r.f32()?,
            temperature_centi_c: r.i16()?,
        })
    }

    fn to_ipc(&self, header: Header) -> RawBaro {
        RawBaro {
            version: PAYLOAD_VERSION,
            header,
            pressure_pa: f64::from(self.pressure_pa),
            temperature_c: f32::from(self.temperature_centi_c) / 100.0,
            ..RawBaro::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ipc_form_is_in_pascal_and_degrees() {
        let header = Header {
            origin_seq: 3,
            ..Header::default()
        };
        let raw = BaroFrame {
            pressure_pa: 101_325.0,
            temperature_centi_c: 1_515,
        }
        .to_ipc(header);
        assert_eq!(raw.pressure_pa, 101_325.0);
        assert!((raw.temperature_c - 15.15).abs() < 1e-5);
        assert_eq!((raw.header, raw.version), (header, PAYLOAD_VERSION));
    }
}
