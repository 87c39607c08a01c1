//! Encoding and decoding of one complete frame. All multi-byte fields are little-endian.
//! Neither direction allocates.

use ipc_types::{MAX_CHANNELS, MAX_TEMPERATURES};

use super::error::{DecodeError, EncodeError, ImuContentError, ValueOutOfRange};
use super::frame::{
    AirspeedFrame, AuxFrame, BaroFrame, Frame, FrameType, ImuFrame, MagFrame, Payload,
};
use super::layout::{
    AIRSPEED_MAX_ABS_PA, AIRSPEED_PAYLOAD_LEN, AIRSPEED_TEMPERATURE_CENTI_C, AUX_PAYLOAD_LEN,
    BARO_PAYLOAD_LEN, CRC_LEN, CRC32C, FRAME_OVERHEAD, HEADER_LEN, LEN_OFFSET, MAG_PAYLOAD_LEN,
    SYNC, TYPE_OFFSET, count_in_range, imu_payload_len, payload_len_plausible,
};

impl Payload {
    /// Payload length on the wire, in bytes. Only the first `n_*` entries of the IMU arrays
    /// count; for an IMU frame with out-of-range channel counts the arrays' capacity is assumed.
    pub fn wire_len(&self) -> usize {
        match self {
            Payload::Imu(imu) => imu_payload_len(
                usize::from(imu.n_gyro).min(MAX_CHANNELS),
                usize::from(imu.n_accel).min(MAX_CHANNELS),
                usize::from(imu.n_temperature).min(MAX_TEMPERATURES),
            ),
            Payload::Baro(_) => BARO_PAYLOAD_LEN,
            Payload::Mag(_) => MAG_PAYLOAD_LEN,
            Payload::Aux(_) => AUX_PAYLOAD_LEN,
            Payload::Airspeed(_) => AIRSPEED_PAYLOAD_LEN,
        }
    }
}

impl Frame {
    /// Length of the encoded frame, header and CRC included.
    pub fn encoded_len(&self) -> usize {
        FRAME_OVERHEAD + self.payload.wire_len()
    }
}

/// Encodes `frame` into the start of `out` and returns the number of bytes written.
///
/// Fails if `out` is too short, if an IMU channel count exceeds `MAX_CHANNELS` /
/// `MAX_TEMPERATURES`, if a gyro/accel count is outside -2048..=2047, or if an airspeed value is
/// not sane ([`airspeed_sane`]). Array entries past the channel counts are not sent.
pub fn encode(frame: &Frame, out: &mut [u8]) -> Result<usize, EncodeError> {
    match &frame.payload {
        Payload::Imu(imu) => validate_imu(imu)?,
        Payload::Airspeed(a) => airspeed_sane(a)?,
        Payload::Baro(_) | Payload::Mag(_) | Payload::Aux(_) => {}
    }
    let payload_len = frame.payload.wire_len();
    let total = FRAME_OVERHEAD + payload_len;
    let available = out.len();
    let out = out.get_mut(..total).ok_or(EncodeError::BufferTooSmall {
        needed: total,
        available,
    })?;

    let mut w = Writer { buf: out, pos: 0 };
    w.bytes(&SYNC);
    w.bytes(&[frame.payload.frame_type() as u8]);
    // Cannot truncate: `wire_len` is at most MAX_PAYLOAD_LEN, which fits a u8 (checked in layout).
    w.bytes(&[payload_len as u8]);
    w.bytes(&frame.seq.to_le_bytes());
    w.bytes(&frame.device_time_us.to_le_bytes());
    match &frame.payload {
        Payload::Imu(imu) => {
            w.bytes(&[imu.n_gyro, imu.n_accel, imu.n_temperature]);
            w.bytes(&imu.status.to_le_bytes());
            w.bytes(&imu.valid_mask.to_le_bytes());
            let samples = imu.gyro_counts[..usize::from(imu.n_gyro)]
                .iter()
                .chain(&imu.accel_counts[..usize::from(imu.n_accel)])
                .chain(&imu.temperature_centi_c[..usize::from(imu.n_temperature)]);
            for v in samples {
                w.bytes(&v.to_le_bytes());
            }
        }
        Payload::Baro(b) => {
            w.bytes(&b.pressure_pa.to_le_bytes());
            w.bytes(&b.temperature_centi_c.to_le_bytes());
        }
        Payload::Mag(m) => {
            for v in m.field_nt {
                w.bytes(&v.to_le_bytes());
            }
        }
        Payload::Aux(a) => w.bytes(&a.foot_pressure.to_le_bytes()),
        Payload::Airspeed(a) => {
            w.bytes(&a.diff_pressure_pa.to_le_bytes());
            w.bytes(&a.temperature_centi_c.to_le_bytes());
        }
    }
    let body_end = total - CRC_LEN;
    let crc = CRC32C.checksum(&w.buf[TYPE_OFFSET..body_end]);
    w.bytes(&crc.to_le_bytes());
    Ok(total)
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

fn validate_imu(imu: &ImuFrame) -> Result<(), EncodeError> {
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
            }
            .into());
        }
    }
    Ok(())
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

/// Total frame length announced by the header at the start of `bytes`, validated as far as the
/// bytes present allow: sync word, frame type, and a payload length plausible for that type.
///
/// Returns `Incomplete` while fewer than 4 bytes are present, so that a decoder can wait for them.
pub fn peek_frame_len(bytes: &[u8]) -> Result<usize, DecodeError> {
    let incomplete = DecodeError::Incomplete { needed: HEADER_LEN };
    match bytes {
        [] => return Err(incomplete),
        [a] if *a == SYNC[0] => return Err(incomplete),
        [a, b, ..] if [*a, *b] == SYNC => {}
        _ => return Err(DecodeError::NoSync),
    }
    let &type_byte = bytes.get(TYPE_OFFSET).ok_or(incomplete)?;
    let frame_type =
        FrameType::from_u8(type_byte).ok_or(DecodeError::UnknownFrameType { value: type_byte })?;
    let len = usize::from(*bytes.get(LEN_OFFSET).ok_or(incomplete)?);
    if !payload_len_plausible(frame_type, len) {
        return Err(DecodeError::BadPayloadLength { frame_type, len });
    }
    Ok(FRAME_OVERHEAD + len)
}

/// Decodes the frame at the start of `bytes` and returns it with the number of bytes it occupies.
/// Bytes after the frame are ignored.
///
/// The order of checks is: header (sync, type, length), CRC, then payload contents (channel
/// counts, 12-bit range, sane airspeed values). A frame is returned only if its CRC matched.
pub fn decode_frame(bytes: &[u8]) -> Result<(Frame, usize), DecodeError> {
    let frame_len = peek_frame_len(bytes)?;
    let incomplete = DecodeError::Incomplete { needed: frame_len };
    let frame = bytes.get(..frame_len).ok_or(incomplete)?;
    // frame_len >= FRAME_OVERHEAD, so the body holds at least the whole header.
    let (body, trailer) = frame.split_at(frame_len - CRC_LEN);
    let received = Reader { buf: trailer }.u32().ok_or(incomplete)?;
    let computed = CRC32C.checksum(&body[TYPE_OFFSET..]);
    if received != computed {
        return Err(DecodeError::CrcMismatch { received, computed });
    }

    let mut r = Reader {
        buf: &body[TYPE_OFFSET..],
    };
    let type_byte = r.u8().ok_or(incomplete)?;
    let _len = r.u8().ok_or(incomplete)?;
    let seq = r.u16().ok_or(incomplete)?;
    let device_time_us = r.u32().ok_or(incomplete)?;
    let frame_type =
        FrameType::from_u8(type_byte).ok_or(DecodeError::UnknownFrameType { value: type_byte })?;
    let payload = decode_payload(frame_type, r.buf)?;
    Ok((
        Frame {
            seq,
            device_time_us,
            payload,
        },
        frame_len,
    ))
}

fn decode_payload(frame_type: FrameType, bytes: &[u8]) -> Result<Payload, DecodeError> {
    // A short read cannot happen once the length checks have passed; should it, the payload
    // length was wrong for its contents.
    let short = DecodeError::BadPayloadLength {
        frame_type,
        len: bytes.len(),
    };
    let mut r = Reader { buf: bytes };
    let payload = match frame_type {
        FrameType::Imu => Payload::Imu(decode_imu(bytes)?),
        FrameType::Baro => Payload::Baro(BaroFrame {
            pressure_pa: r.f32().ok_or(short)?,
            temperature_centi_c: r.i16().ok_or(short)?,
        }),
        FrameType::Mag => Payload::Mag(MagFrame {
            field_nt: [
                r.i32().ok_or(short)?,
                r.i32().ok_or(short)?,
                r.i32().ok_or(short)?,
            ],
        }),
        FrameType::Aux => Payload::Aux(AuxFrame {
            foot_pressure: r.u16().ok_or(short)?,
        }),
        FrameType::Airspeed => {
            let a = AirspeedFrame {
                diff_pressure_pa: r.f32().ok_or(short)?,
                temperature_centi_c: r.i16().ok_or(short)?,
            };
            airspeed_sane(&a)?;
            Payload::Airspeed(a)
        }
    };
    Ok(payload)
}

fn decode_imu(bytes: &[u8]) -> Result<ImuFrame, DecodeError> {
    let short = DecodeError::BadPayloadLength {
        frame_type: FrameType::Imu,
        len: bytes.len(),
    };
    let mut r = Reader { buf: bytes };
    let mut imu = ImuFrame {
        n_gyro: r.u8().ok_or(short)?,
        n_accel: r.u8().ok_or(short)?,
        n_temperature: r.u8().ok_or(short)?,
        status: r.u16().ok_or(short)?,
        valid_mask: r.u32().ok_or(short)?,
        ..ImuFrame::default()
    };
    channel_counts_within_limits(&imu)?;
    let (ng, na, nt) = (
        usize::from(imu.n_gyro),
        usize::from(imu.n_accel),
        usize::from(imu.n_temperature),
    );
    if bytes.len() != imu_payload_len(ng, na, nt) {
        return Err(short);
    }
    let channels = [
        ("gyro_counts", &mut imu.gyro_counts[..ng]),
        ("accel_counts", &mut imu.accel_counts[..na]),
    ];
    for (field, counts) in channels {
        for (index, slot) in counts.iter_mut().enumerate() {
            let value = r.i16().ok_or(short)?;
            if !count_in_range(value) {
                return Err(ImuContentError::CountOutOfRange {
                    field,
                    index,
                    value,
                }
                .into());
            }
            *slot = value;
        }
    }
    for slot in &mut imu.temperature_centi_c[..nt] {
        *slot = r.i16().ok_or(short)?;
    }
    Ok(imu)
}

/// Sequential writer into a buffer already sized to the frame.
struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}

impl Writer<'_> {
    fn bytes(&mut self, b: &[u8]) {
        self.buf[self.pos..self.pos + b.len()].copy_from_slice(b);
        self.pos += b.len();
    }
}

/// Sequential little-endian reader; every read returns `None` past the end instead of panicking.
struct Reader<'a> {
    buf: &'a [u8],
}

impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> Option<[u8; N]> {
        let (head, rest) = self.buf.split_at_checked(N)?;
        self.buf = rest;
        head.try_into().ok()
    }
    fn u8(&mut self) -> Option<u8> {
        self.take::<1>().map(|[b]| b)
    }
    fn u16(&mut self) -> Option<u16> {
        self.take().map(u16::from_le_bytes)
    }
    fn i16(&mut self) -> Option<i16> {
        self.take().map(i16::from_le_bytes)
    }
    fn u32(&mut self) -> Option<u32> {
        self.take().map(u32::from_le_bytes)
    }
    fn i32(&mut self) -> Option<i32> {
        self.take().map(i32::from_le_bytes)
    }
    fn f32(&mut self) -> Option<f32> {
        self.take().map(f32::from_le_bytes)
    }
}
