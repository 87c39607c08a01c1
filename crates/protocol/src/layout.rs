//! Wire layout shared by the encoder and the decoder. `docs/protocol.md` is the prose version of
//! this file; keep the two in step.

use crc::{CRC_32_ISCSI, Crc};
use ipc_types::{MAX_CHANNELS, MAX_TEMPERATURES};

use super::frame::FrameType;

/// Every frame starts with these two bytes.
pub const SYNC: [u8; 2] = [0xA5, 0x5A];

/// Sync (2) + type (1) + payload length (1) + sequence (2) + device time (4).
pub const HEADER_LEN: usize = 10;

/// CRC-32C trailer.
pub const CRC_LEN: usize = 4;

/// Bytes a frame adds around its payload.
pub const FRAME_OVERHEAD: usize = HEADER_LEN + CRC_LEN;

/// Offset of the type byte from the first sync byte.
pub const TYPE_OFFSET: usize = 2;
/// Offset of the payload length byte from the first sync byte.
pub const LEN_OFFSET: usize = 3;
/// Offset of the 16-bit sequence number (little-endian) from the first sync byte.
pub const SEQ_OFFSET: usize = 4;
/// Offset of the 32-bit device time, µs (little-endian), from the first sync byte.
pub const TIME_OFFSET: usize = 6;

/// IMU payload before the sample arrays: n_gyro, n_accel, n_temperature (u8 each), status (u16),
/// valid_mask (u32).
pub const IMU_FIXED_LEN: usize = 9;

/// Largest payload on the wire: an IMU frame with every channel and temperature present.
pub const MAX_PAYLOAD_LEN: usize = IMU_FIXED_LEN + 2 * (2 * MAX_CHANNELS + MAX_TEMPERATURES);

/// Largest frame on the wire, in bytes (95).
pub const MAX_FRAME_LEN: usize = FRAME_OVERHEAD + MAX_PAYLOAD_LEN;

/// Barometer payload: f32 pressure + i16 temperature.
pub const BARO_PAYLOAD_LEN: usize = 6;

/// Magnetometer payload: 3 × i32.
pub const MAG_PAYLOAD_LEN: usize = 12;

/// Auxiliary payload: u16 foot pressure.
pub const AUX_PAYLOAD_LEN: usize = 2;

/// Airspeed payload: f32 differential pressure + i16 temperature.
pub const AIRSPEED_PAYLOAD_LEN: usize = 6;

/// Largest differential pressure an airspeed frame may carry, Pa, either sign: the ±1 psi range of
/// the sensor class (dynamic pressure of about 105 m/s at sea level), rounded up. A value beyond
/// it, or not finite, is refused even under a valid CRC.
pub const AIRSPEED_MAX_ABS_PA: f32 = 7000.0;
/// Temperature range an airspeed frame may carry, hundredths of a °C: the sensor class's
/// operating range, -50 ..= 150 °C.
pub const AIRSPEED_TEMPERATURE_CENTI_C: core::ops::RangeInclusive<i16> = -5000..=15000;

/// Lowest gyro or accelerometer count: channels are signed 12-bit ADC counts.
pub const COUNT_MIN: i16 = -2048;
/// Highest gyro or accelerometer count (the positive converter rail).
pub const COUNT_MAX: i16 = 2047;
/// Counts per converter full scale: full scale maps to ±2048 counts, so one count is full scale / 2048.
pub const COUNTS_PER_FULL_SCALE: f64 = 2048.0;

/// CRC-32C (Castagnoli), computed over the type byte through the end of the payload. A `const`
/// so that the lookup table is built at compile time.
pub(crate) const CRC32C: Crc<u32> = Crc::<u32>::new(&CRC_32_ISCSI);

// The length byte must be able to carry the largest payload.
const _: () = assert!(MAX_PAYLOAD_LEN <= u8::MAX as usize);

/// Whether `len` is a payload length a frame of type `frame_type` can have. Checked from the
/// header alone, so that a corrupt length is rejected before waiting for bytes that may never
/// belong to it.
pub fn payload_len_plausible(frame_type: FrameType, len: usize) -> bool {
    match frame_type {
        // 9 fixed bytes + an even number of sample bytes.
        FrameType::Imu => {
            (IMU_FIXED_LEN..=MAX_PAYLOAD_LEN).contains(&len)
                && (len - IMU_FIXED_LEN).is_multiple_of(2)
        }
        FrameType::Baro => len == BARO_PAYLOAD_LEN,
        FrameType::Mag => len == MAG_PAYLOAD_LEN,
        FrameType::Aux => len == AUX_PAYLOAD_LEN,
        FrameType::Airspeed => len == AIRSPEED_PAYLOAD_LEN,
    }
}

/// IMU payload length for the given channel counts.
pub fn imu_payload_len(n_gyro: usize, n_accel: usize, n_temperature: usize) -> usize {
    IMU_FIXED_LEN + 2 * (n_gyro + n_accel + n_temperature)
}

/// Whether `count` fits the 12-bit ADC range.
pub fn count_in_range(count: i16) -> bool {
    (COUNT_MIN..=COUNT_MAX).contains(&count)
}
