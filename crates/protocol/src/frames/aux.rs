//! The auxiliary frame: the foot-pressure sensor.

use ipc_types::{Header, PAYLOAD_VERSION, RawAux, names};

use super::SensorFrame;
use crate::error::DecodeError;
use crate::frame_type::FrameType;
use crate::wire::{Reader, Writer};

/// Auxiliary payload: u16 foot pressure.
pub const AUX_PAYLOAD_LEN: usize = 2;

/// Auxiliary frame: foot-pressure sensor reading, raw 16-bit (0 = no load, 65535 = full scale).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AuxFrame {
    /// The foot-pressure reading, raw.
    pub foot_pressure: u16,
}

impl SensorFrame for AuxFrame {
    const TYPE: FrameType = FrameType::Aux;
    const MAX_PAYLOAD_LEN: usize = AUX_PAYLOAD_LEN;
    type Ipc = RawAux;
    const TOPIC: &'static str = names::RAW_AUX;

    fn encode(&self, w: &mut Writer<'_>) {
        w.u16(self.foot_pressure);
    }

    fn decode(payload: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Reader::payload(Self::TYPE, payload);
        Ok(Self {
            foot_pressure: r.u16()?,
        })
    }

    fn to_ipc(&self, header: Header) -> RawAux {
        RawAux {
            version: PAYLOAD_VERSION,
            header,
            foot_pressure: f32::from(self.foot_pressure) / f32::from(u16::MAX),
            ..RawAux::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ipc_form_is_a_fraction_of_full_scale() {
        let full = AuxFrame {
            foot_pressure: u16::MAX,
        };
        assert_eq!(full.to_ipc(Header::default()).foot_pressure, 1.0);
        let none = AuxFrame { foot_pressure: 0 };
        assert_eq!(none.to_ipc(Header::default()).foot_pressure, 0.0);
    }
}
