//! Decoded frames → IPC payloads, with the origin header stamped.

use ipc_types::{Header, PAYLOAD_VERSION, RawAirspeed, RawAux, RawBaro, RawImu, RawMag};

use rins_protocol::{AirspeedFrame, AuxFrame, BaroFrame, DecodedFrame, ImuFrame, MagFrame};

/// The header of a decoded frame: its device sequence and time, and when it was received (`rx_ns`).
pub fn origin_header(frame: &DecodedFrame, rx_ns: u64) -> Header {
    Header {
        origin_seq: frame.seq,
        origin_device_time_us: frame.device_time_us,
        origin_rx_ns: rx_ns,
        ..Header::default()
    }
}

/// The raw IMU message of an IMU frame.
pub fn raw_imu(f: &ImuFrame, header: Header) -> RawImu {
    let mut temperature_c = [0.0f32; ipc_types::MAX_TEMPERATURES];
    for (out, centi) in temperature_c.iter_mut().zip(f.temperature_centi_c) {
        *out = f32::from(centi) / 100.0;
    }
    RawImu {
        version: PAYLOAD_VERSION,
        n_gyro: f.n_gyro,
        n_accel: f.n_accel,
        n_temperature: f.n_temperature,
        _pad: [0; 3],
        status: u32::from(f.status),
        valid_mask: f.valid_mask,
        header,
        gyro_counts: f.gyro_counts,
        accel_counts: f.accel_counts,
        temperature_c,
    }
}

/// The raw barometer message of a barometer frame.
pub fn raw_baro(f: &BaroFrame, header: Header) -> RawBaro {
    RawBaro {
        version: PAYLOAD_VERSION,
        header,
        pressure_pa: f64::from(f.pressure_pa),
        temperature_c: f32::from(f.temperature_centi_c) / 100.0,
        ..RawBaro::default()
    }
}

/// The raw magnetometer message of a magnetometer frame.
pub fn raw_mag(f: &MagFrame, header: Header) -> RawMag {
    RawMag {
        version: PAYLOAD_VERSION,
        header,
        // nT on the wire, µT inside.
        field_ut: f.field_nt.map(|nt| nt as f32 / 1000.0),
        ..RawMag::default()
    }
}

/// The raw auxiliary message of an auxiliary frame.
pub fn raw_aux(f: &AuxFrame, header: Header) -> RawAux {
    RawAux {
        version: PAYLOAD_VERSION,
        header,
        foot_pressure: f32::from(f.foot_pressure) / f32::from(u16::MAX),
        ..RawAux::default()
    }
}

/// The raw airspeed message of an airspeed frame.
pub fn raw_airspeed(f: &AirspeedFrame, header: Header) -> RawAirspeed {
    RawAirspeed {
        version: PAYLOAD_VERSION,
        header,
        diff_pressure_pa: f.diff_pressure_pa,
        temperature_c: f32::from(f.temperature_centi_c) / 100.0,
        ..RawAirspeed::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rins_protocol::Payload;

    #[test]
    fn units_are_converted_and_header_kept() {
        let frame = DecodedFrame {
            seq: 70_000,
            device_time_us: 5_000_000_000,
            payload: Payload::Mag(MagFrame {
                field_nt: [25_000, -1_500, 43_301],
            }),
        };
        let h = origin_header(&frame, 42);
        assert_eq!(
            (h.origin_seq, h.origin_device_time_us, h.origin_rx_ns),
            (70_000, 5_000_000_000, 42)
        );
        let Payload::Mag(m) = frame.payload else {
            unreachable!()
        };
        let raw = raw_mag(&m, h);
        assert_eq!(raw.field_ut, [25.0, -1.5, 43.301]);
        let baro = raw_baro(
            &BaroFrame {
                pressure_pa: 101_325.0,
                temperature_centi_c: 1_515,
            },
            h,
        );
        assert!((baro.temperature_c - 15.15).abs() < 1e-5);
        let aux = raw_aux(
            &AuxFrame {
                foot_pressure: u16::MAX,
            },
            h,
        );
        assert_eq!(aux.foot_pressure, 1.0);
        let airspeed = raw_airspeed(
            &AirspeedFrame {
                diff_pressure_pa: 612.5,
                temperature_centi_c: -250,
            },
            h,
        );
        assert_eq!(airspeed.diff_pressure_pa, 612.5);
        assert!((airspeed.temperature_c + 2.5).abs() < 1e-6);
        assert_eq!(airspeed.header, h);
    }
}
