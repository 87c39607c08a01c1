//! Decoded serial frames: what the sensor block sends, in device units.
//! Wire layout and encoding: `docs/protocol.md`, `layout.rs` and `codec.rs`.

use ipc_types::{MAX_CHANNELS, MAX_TEMPERATURES};

/// Frame type byte on the wire.
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameType {
    /// Gyro and accelerometer counts with module temperatures ([`ImuFrame`]).
    Imu = 1,
    /// Barometric pressure and temperature ([`BaroFrame`]).
    Baro = 2,
    /// Three-axis magnetic field ([`MagFrame`]).
    Mag = 3,
    /// Foot-pressure sensor ([`AuxFrame`]).
    Aux = 4,
    /// Pitot differential pressure and temperature ([`AirspeedFrame`]).
    Airspeed = 5,
}

impl FrameType {
    /// Number of frame types: the length of per-type arrays.
    pub const COUNT: usize = 5;

    /// Every type, in [`FrameType::index`] order.
    pub const ALL: [FrameType; Self::COUNT] = [
        FrameType::Imu,
        FrameType::Baro,
        FrameType::Mag,
        FrameType::Aux,
        FrameType::Airspeed,
    ];

    /// The type a wire type byte names; `None` for a byte that names none.
    pub fn from_u8(v: u8) -> Option<Self> {
        match v {
            1 => Some(FrameType::Imu),
            2 => Some(FrameType::Baro),
            3 => Some(FrameType::Mag),
            4 => Some(FrameType::Aux),
            5 => Some(FrameType::Airspeed),
            _ => None,
        }
    }

    /// Index 0..COUNT, for per-type counters.
    pub fn index(self) -> usize {
        self as usize - 1
    }

    /// Lower-case name, for messages.
    pub fn name(self) -> &'static str {
        match self {
            FrameType::Imu => "imu",
            FrameType::Baro => "baro",
            FrameType::Mag => "mag",
            FrameType::Aux => "aux",
            FrameType::Airspeed => "airspeed",
        }
    }
}

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

/// Barometer frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaroFrame {
    /// Static pressure, pascal.
    pub pressure_pa: f32,
    /// Sensor temperature, hundredths of a degree Celsius.
    pub temperature_centi_c: i16,
}

/// Magnetometer frame, body frame (FRD), in nanotesla.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MagFrame {
    /// Field components along the body x, y, z axes, nT.
    pub field_nt: [i32; 3],
}

/// Auxiliary frame: foot-pressure sensor reading, raw 16-bit (0 = no load, 65535 = full scale).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct AuxFrame {
    /// The foot-pressure reading, raw.
    pub foot_pressure: u16,
}

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

/// A frame's contents, by frame type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Payload {
    /// An IMU frame's contents.
    Imu(ImuFrame),
    /// A barometer frame's contents.
    Baro(BaroFrame),
    /// A magnetometer frame's contents.
    Mag(MagFrame),
    /// An auxiliary frame's contents.
    Aux(AuxFrame),
    /// An airspeed frame's contents.
    Airspeed(AirspeedFrame),
}

impl Payload {
    /// The frame type that carries this payload.
    pub fn frame_type(&self) -> FrameType {
        match self {
            Payload::Imu(_) => FrameType::Imu,
            Payload::Baro(_) => FrameType::Baro,
            Payload::Mag(_) => FrameType::Mag,
            Payload::Aux(_) => FrameType::Aux,
            Payload::Airspeed(_) => FrameType::Airspeed,
        }
    }
}

/// A frame as it travels on the wire: 16-bit sequence (per frame type) and 32-bit device time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    /// Sequence number, counted per frame type; wraps at 2^16.
    pub seq: u16,
    /// Device sample clock at the sample, µs; wraps at 2^32 (about 71.6 min).
    pub device_time_us: u32,
    /// The frame's contents.
    pub payload: Payload,
}

/// A frame handed out by the streaming decoder, with sequence and device time extended to 64 bits
/// (they wrap on the wire).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DecodedFrame {
    /// Sequence number of its frame type, extended: increasing within the type (re-based after a
    /// sequence jump, never backwards).
    pub seq: u64,
    /// Device sample clock, µs, extended (re-based after a clock discontinuity, never backwards).
    pub device_time_us: u64,
    /// The frame's contents.
    pub payload: Payload,
}
