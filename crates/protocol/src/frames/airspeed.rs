//! The airspeed frame: a pitot-static differential pressure sensor, with the ranges beyond which
//! its values are refused even under a valid CRC.

use ipc_types::{Header, PAYLOAD_VERSION, RawAirspeed, names};

use super::SensorFrame;
use crate::error::{ContentError, DecodeError, ValueOutOfRange};
use crate::frame_type::FrameType;
use crate::wire::{Reader, Writer};

/// Airspeed payload: f32 differential pressure + i16 temperature.
pub const AIRSPEED_PAYLOAD_LEN: usize = 6;

/// Largest differential pressure an airspeed frame may carry, Pa, either sign: the ±1 psi range of
/// the sensor class (dynamic pressure of about 105 m/s at sea level), rounded up. A value beyond
/// it, or not finite, is refused even under a valid CRC.
pub const AIRSPEED_MAX_ABS_PA: f32 = 7000.0;
/// Temperature range an airspeed frame may carry, hundredths of a °C: the sensor class's
/// operating range, -50 ..= 150 °C.
pub const AIRSPEED_TEMPERATURE_CENTI_C: core::ops::RangeInclusive<i16> = -5000..=15000;

/// Airspeed frame: a pitot-static differential pressure sensor (MS4525DO class), already
/// converted from its bridge counts by the device.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AirspeedFrame {
    /// Differential (total minus static) pressure, pascal: the dynamic pressure ½ρV² plus the
    /// sensor's offset and noise. Slightly negative values are normal at rest.
    pub diff_pressure_pa: f32,
    /// Sensor temperature, hundredths of a degree Celsius.
    pub temperature_centi_c: i16,
}

/// Refuses an airspeed frame with a value its sensor class cannot produce: a differential
/// pressure that is not finite or beyond ±[`AIRSPEED_MAX_ABS_PA`], a temperature outside
/// [`AIRSPEED_TEMPERATURE_CENTI_C`].
pub fn airspeed_sane(a: &AirspeedFrame) -> Result<(), ValueOutOfRange> {
    let max_pa = f64::from(AIRSPEED_MAX_ABS_PA);
    ValueOutOfRange::check(
        FrameType::Airspeed,
        "diff_pressure_pa",
        f64::from(a.diff_pressure_pa),
        -max_pa,
        max_pa,
    )?;
    ValueOutOfRange::check(
        FrameType::Airspeed,
        "temperature_centi_c",
        f64::from(a.temperature_centi_c),
        f64::from(*AIRSPEED_TEMPERATURE_CENTI_C.start()),
        f64::from(*AIRSPEED_TEMPERATURE_CENTI_C.end()),
    )
}

impl SensorFrame for AirspeedFrame {
    const TYPE: FrameType = FrameType::Airspeed;
    const MAX_PAYLOAD_LEN: usize = AIRSPEED_PAYLOAD_LEN;
    type Ipc = RawAirspeed;
    const TOPIC: &'static str = names::RAW_AIRSPEED;

    fn check_sane(&self) -> Result<(), ContentError> {
        Ok(airspeed_sane(self)?)
    }

    fn encode(&self, w: &mut Writer<'_>) {
        w.f32(self.diff_pressure_pa);
        w.i16(self.temperature_centi_c);
    }

    fn decode(payload: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Reader::payload(Self::TYPE, payload);
        Ok(Self {
            diff_pressure_pa: r.f32()?,
            temperature_centi_c: r.i16()?,
        })
    }

    fn to_ipc(&self, header: Header) -> RawAirspeed {
        RawAirspeed {
            version: PAYLOAD_VERSION,
            header,
            diff_pressure_pa: self.diff_pressure_pa,
            temperature_c: f32::from(self.temperature_centi_c) / 100.0,
            ..RawAirspeed::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ipc_form_keeps_pascal_and_the_header() {
        let header = Header {
            origin_seq: 70_000,
            origin_rx_ns: 42,
            ..Header::default()
        };
        let raw = AirspeedFrame {
            diff_pressure_pa: 612.5,
            temperature_centi_c: -250,
        }
        .to_ipc(header);
        assert_eq!(raw.diff_pressure_pa, 612.5);
        assert!((raw.temperature_c + 2.5).abs() < 1e-6);
        assert_eq!(raw.header, header);
    }
}
