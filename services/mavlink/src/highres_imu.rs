//! HIGHRES_IMU: the fused IMU as the autopilot's logs and a ground station's inspector show an IMU —
//! specific force and angular rate in the body (FRD) frame at the measurement's time. Only those
//! six fields are filled: the mask says so, so that a receiver does not take the zeros of the
//! magnetometer, pressure and temperature fields for readings.

use ipc_types::FusedImu;

use crate::dialect::{HIGHRES_IMU_DATA, HighresImuUpdatedFlags};

/// The HIGHRES_IMU of fused sample `f`.
pub fn highres_imu(f: &FusedImu) -> HIGHRES_IMU_DATA {
    let [xacc, yacc, zacc] = f.specific_force_mps2.map(|v| v as f32);
    let [xgyro, ygyro, zgyro] = f.rate_rps.map(|v| v as f32);
    HIGHRES_IMU_DATA {
        time_usec: f.header.origin_rx_ns / 1_000,
        xacc,
        yacc,
        zacc,
        xgyro,
        ygyro,
        zgyro,
        fields_updated: HighresImuUpdatedFlags::HIGHRES_IMU_UPDATED_XACC
            | HighresImuUpdatedFlags::HIGHRES_IMU_UPDATED_YACC
            | HighresImuUpdatedFlags::HIGHRES_IMU_UPDATED_ZACC
            | HighresImuUpdatedFlags::HIGHRES_IMU_UPDATED_XGYRO
            | HighresImuUpdatedFlags::HIGHRES_IMU_UPDATED_YGYRO
            | HighresImuUpdatedFlags::HIGHRES_IMU_UPDATED_ZGYRO,
        ..HIGHRES_IMU_DATA::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::Header;

    #[test]
    fn carries_the_fused_sample_at_its_time() {
        let f = FusedImu {
            header: Header {
                origin_rx_ns: 12_345_678_901,
                ..Header::default()
            },
            rate_rps: [0.1, -0.2, 0.3],
            specific_force_mps2: [0.5, -0.25, -9.75],
            ..FusedImu::default()
        };
        let m = highres_imu(&f);
        assert_eq!(m.time_usec, 12_345_678);
        assert_eq!((m.xacc, m.yacc, m.zacc), (0.5, -0.25, -9.75));
        assert_eq!((m.xgyro, m.ygyro, m.zgyro), (0.1, -0.2, 0.3));
        assert_eq!(m.fields_updated.bits(), 0x3f);
        assert_eq!(m.abs_pressure, 0.0);
    }
}
