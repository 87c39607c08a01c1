//! The magnetometer frame: the three-axis field in the body frame.

use ipc_types::{Header, PAYLOAD_VERSION, RawMag, names};

use super::SensorFrame;
use crate::error::DecodeError;
use crate::frame_type::FrameType;
use crate::wire::{Reader, Writer};

/// Magnetometer payload: 3 × i32.
pub const MAG_PAYLOAD_LEN: usize = 12;

/// Magnetometer frame, body frame (FRD), in nanotesla.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MagFrame {
    /// Field components along the body x, y, z axes, nT.
    pub field_nt: [i32; 3],
}

impl SensorFrame for MagFrame {
    const TYPE: FrameType = FrameType::Mag;
    const MAX_PAYLOAD_LEN: usize = MAG_PAYLOAD_LEN;
    type Ipc = RawMag;
    const TOPIC: &'static str = names::RAW_MAG;

    fn encode(&self, w: &mut Writer<'_>) {
        for v in self.field_nt {
            w.i32(v);
        }
    }

    fn decode(payload: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Reader::payload(Self::TYPE, payload);
        Ok(Self {
            field_nt: [r.i32()?, r.i32()?, r.i32()?],
        })
    }

    fn to_ipc(&self, header: Header) -> RawMag {
        RawMag {
            version: PAYLOAD_VERSION,
            header,
            // nT on the wire, µT inside.
            field_ut: self.field_nt.map(|nt| nt as f32 / 1000.0),
            ..RawMag::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ipc_form_is_in_microtesla() {
        let raw = MagFrame {
            field_nt: [25_000, -1_500, 43_301],
        }
        .to_ipc(Header::default());
        assert_eq!(raw.field_ut, [25.0, -1.5, 43.301]);
    }
}
