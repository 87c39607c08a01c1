//! The IMU frame: a variable number of gyro and accelerometer channels as 12-bit ADC counts, with
//! module temperatures. Its payload length follows from the channel counts it carries.

use ipc_types::{Header, MAX_CHANNELS, MAX_TEMPERATURES, PAYLOAD_VERSION, RawImu, names};

use super::SensorFrame;
use crate::error::{ContentError, DecodeError, ImuContentError};
use crate::frame_type::FrameType;
use crate::wire::{Reader, Writer};

/// IMU payload before the sample arrays: n_gyro, n_accel, n_temperature (u8 each), status (u16),
/// valid_mask (u32).
pub const IMU_FIXED_LEN: usize = 9;

/// Largest IMU payload: every channel and temperature present.
pub const IMU_MAX_PAYLOAD_LEN: usize = IMU_FIXED_LEN + 2 * (2 * MAX_CHANNELS + MAX_TEMPERATURES);

/// Lowest gyro or accelerometer count: channels are signed 12-bit ADC counts.
pub const COUNT_MIN: i16 = -2048;
/// Highest gyro or accelerometer count (the positive converter rail).
pub const COUNT_MAX: i16 = 2047;
/// Counts per converter full scale: full scale maps to ±2048 counts, so one count is full scale / 2048.
pub const COUNTS_PER_FULL_SCALE: f64 = 2048.0;

/// IMU frame: N gyro and N accel channels as signed 12-bit ADC counts (-2048..=2047).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuFrame {
    /// Gyro channels present (at most `MAX_CHANNELS`); the first `n_gyro` entries of
    /// `gyro_counts` are meaningful.
    pub n_gyro: u8,
    /// Accelerometer channels present (at most `MAX_CHANNELS`).
    pub n_accel: u8,
    /// Module temperatures present (at most `MAX_TEMPERATURES`).
    pub n_temperature: u8,
    /// Device status bits (`ipc_types::status`).
    pub status: u16,
    /// Bit i: gyro i valid; bit 16 + i: accel i valid.
    pub valid_mask: u32,
    /// Gyro channel outputs, ADC counts along each channel's sensitive axis; entries past
    /// `n_gyro` are not sent.
    pub gyro_counts: [i16; MAX_CHANNELS],
    /// Accelerometer channel outputs, ADC counts along each channel's sensitive axis; entries past
    /// `n_accel` are not sent.
    pub accel_counts: [i16; MAX_CHANNELS],
    /// Module temperatures, hundredths of a degree Celsius.
    pub temperature_centi_c: [i16; MAX_TEMPERATURES],
}

impl Default for ImuFrame {
    fn default() -> Self {
        Self {
            n_gyro: 0,
            n_accel: 0,
            n_temperature: 0,
            status: 0,
            valid_mask: 0,
            gyro_counts: [0; MAX_CHANNELS],
            accel_counts: [0; MAX_CHANNELS],
            temperature_centi_c: [0; MAX_TEMPERATURES],
        }
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

/// Refuses an IMU frame whose channel counts exceed what the frame format carries, naming the
/// first such count: the same limits bind what is encoded and what is decoded.
fn channel_counts_within_limits(imu: &ImuFrame) -> Result<(), ImuContentError> {
    match [
        ("n_gyro", imu.n_gyro, MAX_CHANNELS),
        ("n_accel", imu.n_accel, MAX_CHANNELS),
        ("n_temperature", imu.n_temperature, MAX_TEMPERATURES),
    ]
    .into_iter()
    .find(|&(_, value, max)| usize::from(value) > max)
    {
        Some((field, value, max)) => Err(ImuContentError::TooManyChannels { field, value, max }),
        None => Ok(()),
    }
}

/// Refuses channel counts beyond the format's limits, then the first gyro or accelerometer count
/// (gyros first, in channel order) outside the 12-bit range.
fn validate_imu(imu: &ImuFrame) -> Result<(), ImuContentError> {
    channel_counts_within_limits(imu)?;
    let channels = [
        ("gyro_counts", &imu.gyro_counts[..usize::from(imu.n_gyro)]),
        (
            "accel_counts",
            &imu.accel_counts[..usize::from(imu.n_accel)],
        ),
    ];
    for (field, counts) in channels {
        if let Some((index, &value)) = counts
            .iter()
            .enumerate()
            .find(|(_, c)| !count_in_range(**c))
        {
            return Err(ImuContentError::CountOutOfRange {
                field,
                index,
                value,
            });
        }
    }
    Ok(())
}

impl SensorFrame for ImuFrame {
    const TYPE: FrameType = FrameType::Imu;
    const MAX_PAYLOAD_LEN: usize = IMU_MAX_PAYLOAD_LEN;
    type Ipc = RawImu;
    const TOPIC: &'static str = names::RAW_IMU;

    /// The fixed part plus an even number of sample bytes.
    fn len_plausible(len: usize) -> bool {
        (IMU_FIXED_LEN..=IMU_MAX_PAYLOAD_LEN).contains(&len)
            && (len - IMU_FIXED_LEN).is_multiple_of(2)
    }

    /// Only the first `n_*` entries of the arrays count; for out-of-range channel counts the
    /// arrays' capacity is assumed.
    fn wire_len(&self) -> usize {
        imu_payload_len(
            usize::from(self.n_gyro).min(MAX_CHANNELS),
            usize::from(self.n_accel).min(MAX_CHANNELS),
            usize::from(self.n_temperature).min(MAX_TEMPERATURES),
        )
    }

    fn check_sane(&self) -> Result<(), ContentError> {
        Ok(validate_imu(self)?)
    }

    fn encode(&self, w: &mut Writer<'_>) {
        w.bytes(&[self.n_gyro, self.n_accel, self.n_temperature]);
        w.u16(self.status);
        w.u32(self.valid_mask);
        let samples = self.gyro_counts[..usize::from(self.n_gyro)]
            .iter()
            .chain(&self.accel_counts[..usize::from(self.n_accel)])
            .chain(&self.temperature_centi_c[..usize::from(self.n_temperature)]);
        for &v in samples {
            w.i16(v);
        }
    }

    /// Checks the channel counts before trusting them to size the arrays, and the payload length
    /// against them; the 12-bit range is left to [`SensorFrame::check_sane`].
    fn decode(payload: &[u8]) -> Result<Self, DecodeError> {
        let mut r = Reader::payload(Self::TYPE, payload);
        let mut imu = ImuFrame {
            n_gyro: r.u8()?,
            n_accel: r.u8()?,
            n_temperature: r.u8()?,
            status: r.u16()?,
            valid_mask: r.u32()?,
            ..ImuFrame::default()
        };
        channel_counts_within_limits(&imu)?;
        let (ng, na, nt) = (
            usize::from(imu.n_gyro),
            usize::from(imu.n_accel),
            usize::from(imu.n_temperature),
        );
        if payload.len() != imu_payload_len(ng, na, nt) {
            return Err(Reader::bad_length(Self::TYPE, payload));
        }
        let slots = imu.gyro_counts[..ng]
            .iter_mut()
            .chain(&mut imu.accel_counts[..na])
            .chain(&mut imu.temperature_centi_c[..nt]);
        for slot in slots {
            *slot = r.i16()?;
        }
        Ok(imu)
    }

    fn to_ipc(&self, header: Header) -> RawImu {
        let mut temperature_c = [0.0f32; MAX_TEMPERATURES];
        for (out, centi) in temperature_c.iter_mut().zip(self.temperature_centi_c) {
            *out = f32::from(centi) / 100.0;
        }
        RawImu {
            version: PAYLOAD_VERSION,
            n_gyro: self.n_gyro,
            n_accel: self.n_accel,
            n_temperature: self.n_temperature,
            _pad: [0; 3],
            status: u32::from(self.status),
            valid_mask: self.valid_mask,
            header,
            gyro_counts: self.gyro_counts,
            accel_counts: self.accel_counts,
            temperature_c,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ipc_form_keeps_counts_and_converts_temperatures() {
        let mut imu = ImuFrame {
            n_gyro: 2,
            n_accel: 1,
            n_temperature: 2,
            status: 0x8001,
            valid_mask: 0x0001_0003,
            ..ImuFrame::default()
        };
        imu.gyro_counts[..2].copy_from_slice(&[-2048, 2047]);
        imu.accel_counts[0] = 5;
        imu.temperature_centi_c[..2].copy_from_slice(&[2_550, -1_000]);
        let raw = imu.to_ipc(Header::default());
        assert_eq!((raw.n_gyro, raw.n_accel, raw.n_temperature), (2, 1, 2));
        assert_eq!((raw.status, raw.valid_mask), (0x8001, 0x0001_0003));
        assert_eq!(raw.gyro_counts, imu.gyro_counts);
        assert_eq!(raw.accel_counts, imu.accel_counts);
        assert!((raw.temperature_c[0] - 25.5).abs() < 1e-5);
        assert!((raw.temperature_c[1] + 10.0).abs() < 1e-5);
        assert_eq!(raw.version, PAYLOAD_VERSION);
    }

    #[test]
    fn decoding_checks_channel_counts_before_the_length() {
        let mut payload = [0u8; IMU_FIXED_LEN];
        payload[0] = 17;
        assert_eq!(
            ImuFrame::decode(&payload),
            Err(DecodeError::Content(ImuContentError::TooManyChannels {
                field: "n_gyro",
                value: 17,
                max: MAX_CHANNELS,
            }))
        );
        payload[0] = 1;
        assert_eq!(
            ImuFrame::decode(&payload),
            Err(DecodeError::BadPayloadLength {
                frame_type: FrameType::Imu,
                len: IMU_FIXED_LEN,
            })
        );
    }
}
