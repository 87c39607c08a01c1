//! The only contract shared between rins processes: fixed-size `#[repr(C)]` payloads that travel
//! zero-copy over iceoryx2 shared memory, the common header that makes latency measurable end to end,
//! and the service names.
//!
//! Every payload starts with a `version` field; a consumer rejects a payload whose version differs
//! from [`PAYLOAD_VERSION`] instead of misreading it.

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

pub mod names;

/// Version of every payload layout in this crate. Bump it on any layout change.
pub const PAYLOAD_VERSION: u16 = 5;

/// Up to this many single-axis channels per sensor type (gyro, accelerometer).
pub const MAX_CHANNELS: usize = 16;

/// Up to this many module temperature sensors in the sensor block.
pub const MAX_TEMPERATURES: usize = 4;

/// Pipeline stages that stamp their publish time into [`Header::stage_pub_ns`].
#[repr(usize)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    Acquisition = 0,
    Fusion = 1,
    Altimeter = 2,
    Navigator = 3,
}

impl Stage {
    pub const COUNT: usize = 4;
    pub const ALL: [Stage; Stage::COUNT] = [
        Stage::Acquisition,
        Stage::Fusion,
        Stage::Altimeter,
        Stage::Navigator,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Stage::Acquisition => "acquisition",
            Stage::Fusion => "fusion",
            Stage::Altimeter => "altimeter",
            Stage::Navigator => "navigator",
        }
    }
}

/// Carried by every message: where the data came from and when each stage published it.
/// Times are CLOCK_MONOTONIC nanoseconds; 0 means "stage not passed".
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
pub struct Header {
    /// Sequence number of the originating serial frame, extended to 64 bits by acquisition.
    pub origin_seq: u64,
    /// Device time of the originating frame in microseconds, extended to 64 bits.
    pub origin_device_time_us: u64,
    /// When acquisition had the whole originating frame (CLOCK_MONOTONIC ns).
    pub origin_rx_ns: u64,
    /// Publish time of each stage passed, indexed by [`Stage`].
    pub stage_pub_ns: [u64; Stage::COUNT],
}

impl Header {
    pub fn stamp(&mut self, stage: Stage, now_ns: u64) {
        self.stage_pub_ns[stage as usize] = now_ns;
    }

    pub fn stage_ns(&self, stage: Stage) -> u64 {
        self.stage_pub_ns[stage as usize]
    }
}

/// Device status bits carried in [`RawImu::status`].
pub mod status {
    /// The device reports an internal error (self-test failed, bus error).
    pub const DEVICE_ERROR: u32 = 1 << 0;
    /// At least one channel is saturated in this frame.
    pub const SATURATION: u32 = 1 << 1;
}

/// One raw IMU frame: every gyro and accelerometer channel in 12-bit signed ADC counts.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawImu")]
pub struct RawImu {
    pub version: u16,
    pub n_gyro: u8,
    pub n_accel: u8,
    pub n_temperature: u8,
    pub _pad: [u8; 3],
    /// Device status bits, see [`status`].
    pub status: u32,
    /// Bit i: gyro channel i valid; bit 16 + i: accel channel i valid.
    pub valid_mask: u32,
    pub header: Header,
    pub gyro_counts: [i16; MAX_CHANNELS],
    pub accel_counts: [i16; MAX_CHANNELS],
    /// Module temperatures in degrees Celsius.
    pub temperature_c: [f32; MAX_TEMPERATURES],
}

impl Default for RawImu {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            n_gyro: 0,
            n_accel: 0,
            n_temperature: 0,
            _pad: [0; 3],
            status: 0,
            valid_mask: 0,
            header: Header::default(),
            gyro_counts: [0; MAX_CHANNELS],
            accel_counts: [0; MAX_CHANNELS],
            temperature_c: [0.0; MAX_TEMPERATURES],
        }
    }
}

/// One raw barometer sample.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawBaro")]
pub struct RawBaro {
    pub version: u16,
    pub _pad: [u8; 6],
    pub header: Header,
    pub pressure_pa: f64,
    pub temperature_c: f32,
    pub _pad2: u32,
}

/// One raw magnetometer sample, body frame (FRD), microtesla.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawMag")]
pub struct RawMag {
    pub version: u16,
    pub _pad: [u8; 6],
    pub header: Header,
    pub field_ut: [f32; 3],
    pub _pad2: u32,
}

/// One auxiliary sample: foot-pressure (force-sensitive resistor) reading, normalised 0..1.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RawAux")]
pub struct RawAux {
    pub version: u16,
    pub _pad: [u8; 6],
    pub header: Header,
    pub foot_pressure: f32,
    pub _pad2: u32,
}

/// State of one redundant channel as judged by fusion.
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ChannelState {
    #[default]
    Ok = 0,
    Suspect = 1,
    Excluded = 2,
    /// Not fitted in this sensor block.
    Absent = 3,
}

impl ChannelState {
    pub fn from_u8(v: u8) -> Self {
        match v {
            0 => ChannelState::Ok,
            1 => ChannelState::Suspect,
            2 => ChannelState::Excluded,
            _ => ChannelState::Absent,
        }
    }
}

/// Why a channel is suspect or excluded ([`FusedImu::gyro_reason`], [`FusedImu::accel_reason`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FaultReason {
    #[default]
    None = 0,
    /// The device flagged the channel invalid, or its samples stopped arriving.
    Missing = 1,
    /// The device reported an error for the channel's module.
    DeviceError = 2,
    /// The channel sits at the end of the converter range.
    Saturated = 3,
    /// The channel's value froze while the others varied.
    Stuck = 4,
    /// The channel's noise is far above its peers'.
    Noisy = 5,
    /// Isolated by the parity test (generalised likelihood test).
    Parity = 6,
    /// Isolated against the gravity / zero-rate reference while stationary.
    StationaryReference = 7,
    /// The module's temperature is outside the calibrated range.
    Temperature = 8,
}

impl FaultReason {
    pub const ALL: [FaultReason; 9] = [
        FaultReason::None,
        FaultReason::Missing,
        FaultReason::DeviceError,
        FaultReason::Saturated,
        FaultReason::Stuck,
        FaultReason::Noisy,
        FaultReason::Parity,
        FaultReason::StationaryReference,
        FaultReason::Temperature,
    ];

    pub fn from_u8(v: u8) -> Self {
        Self::ALL
            .get(v as usize)
            .copied()
            .unwrap_or(FaultReason::None)
    }

    pub fn name(self) -> &'static str {
        match self {
            FaultReason::None => "none",
            FaultReason::Missing => "missing",
            FaultReason::DeviceError => "device-error",
            FaultReason::Saturated => "saturated",
            FaultReason::Stuck => "stuck",
            FaultReason::Noisy => "noisy",
            FaultReason::Parity => "parity",
            FaultReason::StationaryReference => "stationary-reference",
            FaultReason::Temperature => "temperature",
        }
    }
}

/// Body rate and specific force fused from the redundant channels.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FusedImu")]
pub struct FusedImu {
    pub version: u16,
    pub n_gyro: u8,
    pub n_accel: u8,
    pub flags: u32,
    pub header: Header,
    /// Body rate, FRD, rad/s.
    pub rate_rps: [f64; 3],
    /// Specific force, FRD, m/s².
    pub specific_force_mps2: [f64; 3],
    /// Variance of each rate axis, (rad/s)².
    pub rate_var: [f64; 3],
    /// Variance of each specific-force axis, (m/s²)².
    pub specific_force_var: [f64; 3],
    /// Per-channel state, [`ChannelState`] as u8.
    pub gyro_state: [u8; MAX_CHANNELS],
    pub accel_state: [u8; MAX_CHANNELS],
    /// Per-channel [`FaultReason`] as u8 (`None` for channels that are Ok).
    pub gyro_reason: [u8; MAX_CHANNELS],
    pub accel_reason: [u8; MAX_CHANNELS],
    /// Parity test statistic per sensor type (0 when no parity space).
    pub gyro_test_statistic: f32,
    pub accel_test_statistic: f32,
}

/// Bits of [`FusedImu::flags`].
pub mod fused_flags {
    pub const GYRO_FAULT_DETECTED_NOT_ISOLATED: u32 = 1 << 0;
    pub const ACCEL_FAULT_DETECTED_NOT_ISOLATED: u32 = 1 << 1;
    /// Fewer than three usable channels of a type: the solution is not valid.
    pub const GYRO_INSUFFICIENT: u32 = 1 << 2;
    pub const ACCEL_INSUFFICIENT: u32 = 1 << 3;
    /// Fusion is still measuring the per-channel gyro biases at rest: the rate is not yet
    /// bias-corrected, so a navigator must not start its own static alignment on it.
    pub const GYRO_REST_BIAS_PENDING: u32 = 1 << 4;
    /// Fewer than three channels of the type are off the converter rails: the whole block reads
    /// full scale. The true value lies beyond the range, so the solution is not valid (a block
    /// fault or an over-range, never motion to integrate).
    pub const GYRO_SATURATED: u32 = 1 << 5;
    pub const ACCEL_SATURATED: u32 = 1 << 6;
    /// The raw frame did not match the configured sensor block (payload version or channel
    /// counts): nothing was fused, the sample only carries the frame's header onwards so that
    /// downstream stages see the input and why it is unusable.
    pub const INPUT_REJECTED: u32 = 1 << 7;
}

impl Default for FusedImu {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            n_gyro: 0,
            n_accel: 0,
            flags: 0,
            header: Header::default(),
            rate_rps: [0.0; 3],
            specific_force_mps2: [0.0; 3],
            rate_var: [0.0; 3],
            specific_force_var: [0.0; 3],
            gyro_state: [ChannelState::Absent as u8; MAX_CHANNELS],
            accel_state: [ChannelState::Absent as u8; MAX_CHANNELS],
            gyro_reason: [0; MAX_CHANNELS],
            accel_reason: [0; MAX_CHANNELS],
            gyro_test_statistic: 0.0,
            accel_test_statistic: 0.0,
        }
    }
}

/// Barometric altitude.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::Altitude")]
pub struct Altitude {
    pub version: u16,
    pub valid: u8,
    pub _pad: [u8; 5],
    pub header: Header,
    /// Height above mean sea level (ISA with the configured QNH), metres.
    pub height_m: f64,
    /// Vertical speed, positive up, m/s.
    pub vertical_speed_mps: f64,
    /// Variance of `height_m`, m².
    pub height_var: f64,
}

/// Bits of [`NavState::aiding`].
pub mod aiding {
    pub const BARO: u32 = 1 << 0;
    pub const MAG: u32 = 1 << 1;
    pub const ZUPT: u32 = 1 << 2;
    pub const HUPT: u32 = 1 << 3;
    /// The tilt is being re-levelled from gravity (after the IMU stopped propagating the attitude).
    pub const GRAVITY: u32 = 1 << 4;
    /// Baro aiding is configured but no reading arrived within the aiding timeout: the altitude
    /// coasts on the inertial solution.
    pub const BARO_STALE: u32 = 1 << 8;
    /// Magnetometer aiding is configured but no reading arrived within the aiding timeout: the
    /// heading coasts on the gyros.
    pub const MAG_STALE: u32 = 1 << 9;
}

/// Aiding sources counted in [`NavState::aiding_accepted`] / [`NavState::aiding_rejected`], in
/// this order: baro, mag, zupt, hupt, gravity.
pub const AIDING_SOURCES: usize = 5;

/// Navigator mode, [`NavState::mode`].
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum NavMode {
    /// Collecting the static alignment window.
    #[default]
    Aligning = 0,
    /// Aligned and navigating.
    Navigating = 1,
    /// Navigating on inertial only: an aiding source expected by the profile is missing.
    Coasting = 2,
    /// Aligned, but the solution's integrity is [`Integrity::Invalid`]: it must not be used.
    Invalid = 3,
}

impl NavMode {
    pub fn from_u8(v: u8) -> Self {
        match v {
            1 => NavMode::Navigating,
            2 => NavMode::Coasting,
            3 => NavMode::Invalid,
            _ => NavMode::Aligning,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            NavMode::Aligning => "aligning",
            NavMode::Navigating => "navigating",
            NavMode::Coasting => "coasting",
            NavMode::Invalid => "invalid",
        }
    }

    /// A solution a consumer may use: aligned and not invalid.
    pub fn is_usable(self) -> bool {
        matches!(self, NavMode::Navigating | NavMode::Coasting)
    }
}

/// How far the navigation solution can be trusted, [`NavState::integrity`]: the navigator's own
/// judgement from its filter's consistency and its input (see [`integrity_reason`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Integrity {
    /// Consistent: use it.
    #[default]
    Ok = 0,
    /// Usable with care: an aiding source is inconsistent or silent, an uncertainty is beyond its
    /// limit, or the solution is recovering from an invalid episode.
    Degraded = 1,
    /// Not usable: the solution is not being propagated, or nothing that aids it agrees with it.
    Invalid = 2,
}

impl Integrity {
    pub const ALL: [Integrity; 3] = [Integrity::Ok, Integrity::Degraded, Integrity::Invalid];

    /// Unknown values read as `Invalid`: a consumer must not trust what it cannot read.
    pub fn from_u8(v: u8) -> Self {
        Self::ALL
            .get(usize::from(v))
            .copied()
            .unwrap_or(Integrity::Invalid)
    }

    pub fn name(self) -> &'static str {
        match self {
            Integrity::Ok => "ok",
            Integrity::Degraded => "degraded",
            Integrity::Invalid => "invalid",
        }
    }
}

/// Why the integrity is not [`Integrity::Ok`], bits of [`NavState::integrity_reasons`].
pub mod integrity_reason {
    /// Fused IMU samples arrive without a usable solution (too few channels of a type, the block
    /// saturated, frames rejected): the state is not propagated. Invalid beyond the outage limit.
    pub const IMU_UNUSABLE: u32 = 1 << 0;
    /// The device time does not advance from sample to sample (or jumps): nothing is integrated.
    pub const TIME_NOT_ADVANCING: u32 = 1 << 1;
    /// Every configured aiding source disagrees with the solution persistently.
    pub const ALL_AIDING_REJECTED: u32 = 1 << 2;
    /// Baro heights persistently rejected, or their normalised innovations too large.
    pub const BARO_INCONSISTENT: u32 = 1 << 3;
    /// Magnetometer headings persistently rejected, or their normalised innovations too large.
    pub const MAG_INCONSISTENT: u32 = 1 << 4;
    /// Zero-velocity (or stance heading) updates persistently rejected or inconsistent.
    pub const ZUPT_INCONSISTENT: u32 = 1 << 5;
    /// An error standard deviation (tilt, heading, vertical, horizontal) beyond its limit.
    pub const COVARIANCE: u32 = 1 << 6;
    /// Back from an invalid episode or a reset: held degraded until the aiding confirms it.
    pub const RECOVERING: u32 = 1 << 7;
    /// The filter state is not finite.
    pub const NON_FINITE: u32 = 1 << 8;
    /// A configured aiding source is silent: the filter coasts on the inertial solution.
    pub const AIDING_STALE: u32 = 1 << 9;

    /// Every reason with its name, in bit order.
    pub const NAMES: [(u32, &str); 10] = [
        (IMU_UNUSABLE, "imu-unusable"),
        (TIME_NOT_ADVANCING, "time-not-advancing"),
        (ALL_AIDING_REJECTED, "all-aiding-rejected"),
        (BARO_INCONSISTENT, "baro-inconsistent"),
        (MAG_INCONSISTENT, "mag-inconsistent"),
        (ZUPT_INCONSISTENT, "zupt-inconsistent"),
        (COVARIANCE, "covariance"),
        (RECOVERING, "recovering"),
        (NON_FINITE, "non-finite"),
        (AIDING_STALE, "aiding-stale"),
    ];

    /// The names of the bits set in `reasons`, comma-separated (empty for none).
    pub fn describe(reasons: u32) -> String {
        let names: Vec<&str> = NAMES
            .iter()
            .filter(|(bit, _)| reasons & bit != 0)
            .map(|(_, name)| *name)
            .collect();
        names.join(",")
    }
}

/// Length of [`NavState::covariance_diag`]: attitude error, velocity, position, gyro bias, accel bias.
pub const NAV_STATES: usize = 15;

/// Navigation solution.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::NavState")]
pub struct NavState {
    pub version: u16,
    /// [`NavMode`] as u8.
    pub mode: u8,
    /// Navigator lane that computed this solution (0 = primary, 1 = hot standby).
    pub lane: u8,
    /// Aiding sources used in this solution, bits of [`aiding`].
    pub aiding: u32,
    pub header: Header,
    /// Attitude quaternion body (FRD) → NED, Hamilton, scalar first.
    pub quaternion: [f64; 4],
    /// Velocity NED, m/s.
    pub velocity_ned_mps: [f64; 3],
    /// Latitude, longitude in radians; altitude above mean sea level in metres.
    pub latitude_rad: f64,
    pub longitude_rad: f64,
    pub altitude_m: f64,
    pub covariance_diag: [f64; NAV_STATES],
    /// Updates accepted per aiding source since alignment (baro, mag, zupt, hupt, gravity).
    pub aiding_accepted: [u32; AIDING_SOURCES],
    /// Updates rejected by the innovation gate per aiding source since alignment.
    pub aiding_rejected: [u32; AIDING_SOURCES],
    /// `header.origin_seq` of the first sample of this solution (alignment completed or state taken
    /// over from the other lane); 0 while aligning. A lane selector trusts a solution only once it
    /// has run for a while, so that a lane that just reset is not chosen.
    pub solution_start_seq: u64,
    /// Estimated gyro bias (body, rad/s) and accelerometer bias (body, m/s²): with the attitude,
    /// velocity, position and covariance they are the whole filter state, so that a restarted lane
    /// can take over its peer's solution in flight.
    pub gyro_bias_rps: [f64; 3],
    pub accel_bias_mps2: [f64; 3],
    /// [`Integrity`] as u8.
    pub integrity: u8,
    pub _pad: [u8; 3],
    /// Why the integrity is not ok, bits of [`integrity_reason`].
    pub integrity_reasons: u32,
}

impl Default for NavState {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            mode: NavMode::Aligning as u8,
            lane: 0,
            aiding: 0,
            header: Header::default(),
            quaternion: [1.0, 0.0, 0.0, 0.0],
            velocity_ned_mps: [0.0; 3],
            latitude_rad: 0.0,
            longitude_rad: 0.0,
            altitude_m: 0.0,
            covariance_diag: [0.0; NAV_STATES],
            aiding_accepted: [0; AIDING_SOURCES],
            aiding_rejected: [0; AIDING_SOURCES],
            solution_start_seq: 0,
            gyro_bias_rps: [0.0; 3],
            accel_bias_mps2: [0.0; 3],
            integrity: Integrity::Ok as u8,
            _pad: [0; 3],
            integrity_reasons: 0,
        }
    }
}

/// Simulator ground truth for one IMU frame (same `header.origin_seq` as the frame).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::Truth")]
pub struct Truth {
    pub version: u16,
    pub _pad: [u8; 6],
    pub header: Header,
    pub quaternion: [f64; 4],
    pub velocity_ned_mps: [f64; 3],
    pub latitude_rad: f64,
    pub longitude_rad: f64,
    pub altitude_m: f64,
}

impl Default for Truth {
    fn default() -> Self {
        Self {
            version: PAYLOAD_VERSION,
            _pad: [0; 6],
            header: Header::default(),
            quaternion: [1.0, 0.0, 0.0, 0.0],
            velocity_ned_mps: [0.0; 3],
            latitude_rad: 0.0,
            longitude_rad: 0.0,
            altitude_m: 0.0,
        }
    }
}

/// Which redundant sensor type a command addresses.
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SensorType {
    Gyro = 0,
    Accel = 1,
}

impl SensorType {
    pub fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(SensorType::Gyro),
            1 => Some(SensorType::Accel),
            _ => None,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            SensorType::Gyro => "gyro",
            SensorType::Accel => "accel",
        }
    }
}

/// Fault the simulator applies to one channel ([`SimControl::fault`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SimFault {
    /// Remove any fault from the channel.
    Clear = 0,
    /// The channel stops: flagged invalid.
    Dead = 1,
    /// The channel repeats its last value.
    Stuck = 2,
    /// A bias step of `param` (SI units: rad/s or m/s²).
    BiasStep = 3,
    /// A bias ramp of `param` per second.
    Ramp = 4,
    /// White noise multiplied by `param`.
    Noise = 5,
    /// The channel reads full scale.
    Saturate = 6,
    /// The channel drops out for the first half of every `param` seconds.
    Intermittent = 7,
    /// The whole serial line goes away for `param` seconds, like a pulled cable: the device's
    /// port vanishes and comes back as a new one. Addresses no channel: [`SimControl::sensor`] is
    /// [`SimControl::WHOLE_DEVICE`] and `channel` 0.
    Disconnect = 8,
}

impl SimFault {
    pub const ALL: [SimFault; 9] = [
        SimFault::Clear,
        SimFault::Dead,
        SimFault::Stuck,
        SimFault::BiasStep,
        SimFault::Ramp,
        SimFault::Noise,
        SimFault::Saturate,
        SimFault::Intermittent,
        SimFault::Disconnect,
    ];

    pub fn from_u8(v: u8) -> Option<Self> {
        Self::ALL.get(v as usize).copied()
    }

    pub fn name(self) -> &'static str {
        match self {
            SimFault::Clear => "clear",
            SimFault::Dead => "dead",
            SimFault::Stuck => "stuck",
            SimFault::BiasStep => "bias",
            SimFault::Ramp => "ramp",
            SimFault::Noise => "noise",
            SimFault::Saturate => "saturate",
            SimFault::Intermittent => "intermittent",
            SimFault::Disconnect => "disconnect",
        }
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }
}

/// Command to the simulator: apply a fault to one channel ("killing a sensor").
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::SimControl")]
pub struct SimControl {
    pub version: u16,
    /// [`SensorType`] as u8.
    pub sensor: u8,
    pub channel: u8,
    /// [`SimFault`] as u8.
    pub fault: u8,
    pub _pad: [u8; 3],
    /// Fault parameter, see [`SimFault`].
    pub param: f64,
}

impl SimControl {
    /// [`SimControl::sensor`] of a fault of the whole device ([`SimFault::Disconnect`]): no
    /// [`SensorType`], so that consumers of channel faults pass it by.
    pub const WHOLE_DEVICE: u8 = u8::MAX;
}

/// What the simulator did with one [`SimControl`] command ([`FaultApplied::outcome`]).
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultOutcome {
    /// The fault (or its clearing) took effect at [`FaultApplied::device_time_us`].
    Applied = 0,
    /// The command named a sensor type or fault kind the simulator does not know.
    UnknownCommand = 1,
    /// The sensor block has no such channel.
    NoSuchChannel = 2,
    /// The fault parameter is out of range (e.g. a noise factor below 1).
    InvalidParameter = 3,
}

impl FaultOutcome {
    pub const ALL: [FaultOutcome; 4] = [
        FaultOutcome::Applied,
        FaultOutcome::UnknownCommand,
        FaultOutcome::NoSuchChannel,
        FaultOutcome::InvalidParameter,
    ];

    pub fn from_u8(v: u8) -> Option<Self> {
        Self::ALL.get(v as usize).copied()
    }

    pub fn name(self) -> &'static str {
        match self {
            FaultOutcome::Applied => "applied",
            FaultOutcome::UnknownCommand => "unknown-command",
            FaultOutcome::NoSuchChannel => "no-such-channel",
            FaultOutcome::InvalidParameter => "invalid-parameter",
        }
    }
}

/// Published by the simulator for every fault command it handled (scheduled or received on
/// [`names::SIM_CONTROL`]), so that detection and isolation delays can be measured in device time.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FaultApplied")]
pub struct FaultApplied {
    pub version: u16,
    /// [`SensorType`] as u8, as given in the command.
    pub sensor: u8,
    pub channel: u8,
    /// [`SimFault`] as u8, as given in the command.
    pub fault: u8,
    /// [`FaultOutcome`] as u8.
    pub outcome: u8,
    pub _pad: [u8; 2],
    /// Device time of the first IMU sample the fault affects, µs since the simulator started (the
    /// time base of [`Header::origin_device_time_us`]).
    pub device_time_us: u64,
    /// The command's parameter, see [`SimFault`].
    pub param: f64,
}

/// Command to fusion: return an excluded channel to service (exclusions latch otherwise).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FusionControl")]
pub struct FusionControl {
    pub version: u16,
    /// [`SensorType`] as u8.
    pub sensor: u8,
    pub channel: u8,
    pub _pad: [u8; 4],
}

/// Which process a [`Health`] message speaks for.
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ServiceKind {
    Simulator = 0,
    Acquisition = 1,
    Fusion = 2,
    Altimeter = 3,
    Navigator = 4,
    Watchdog = 5,
    /// The hot-standby navigator lane (lane 1).
    NavigatorStandby = 6,
}

impl ServiceKind {
    /// The navigator process of each lane, [`NavState::lane`].
    pub const NAVIGATOR_LANES: [ServiceKind; 2] =
        [ServiceKind::Navigator, ServiceKind::NavigatorStandby];

    pub const ALL: [ServiceKind; 7] = [
        ServiceKind::Simulator,
        ServiceKind::Acquisition,
        ServiceKind::Fusion,
        ServiceKind::Altimeter,
        ServiceKind::Navigator,
        ServiceKind::Watchdog,
        ServiceKind::NavigatorStandby,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ServiceKind::Simulator => "sim",
            ServiceKind::Acquisition => "acquisition",
            ServiceKind::Fusion => "fusion",
            ServiceKind::Altimeter => "altimeter",
            ServiceKind::Navigator => "navigator",
            ServiceKind::Watchdog => "watchdog",
            ServiceKind::NavigatorStandby => "navigator-standby",
        }
    }

    pub fn from_u8(v: u8) -> Option<Self> {
        Self::ALL.get(v as usize).copied()
    }

    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// Periodic heartbeat and counters of one process.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::Health")]
pub struct Health {
    pub version: u16,
    /// [`ServiceKind`] as u8.
    pub service: u8,
    pub _pad: [u8; 1],
    pub pid: u32,
    /// CLOCK_MONOTONIC ns when this heartbeat was published.
    pub now_ns: u64,
    /// Messages taken in and published since start.
    pub received: u64,
    pub published: u64,
    /// Serial frames with a bad CRC (acquisition).
    pub crc_errors: u64,
    /// Frames missing from the device's sequence (acquisition), or input samples lost (others).
    pub lost: u64,
    /// Serial frames with a valid CRC but malformed content: unknown type, bad length, channel
    /// counts or samples out of range (acquisition).
    pub malformed: u64,
    /// Serial frames whose sequence number was received before, not published (acquisition).
    pub duplicates: u64,
    /// Serial frames that arrived after a later one of their type (reordered), not published and
    /// not counted in `lost` (acquisition).
    pub late: u64,
    /// Device sequence-counter discontinuities, re-based without counting losses (acquisition).
    pub seq_jumps: u64,
    /// Device-clock discontinuities, re-based on the receive clock (acquisition).
    pub time_rebases: u64,
    /// Bytes skipped while resynchronising (acquisition).
    pub resync_bytes: u64,
    /// Times the input device was reopened (acquisition).
    pub reconnects: u64,
    /// Payloads rejected for a wrong version or malformed content.
    pub rejected: u64,
    /// Periods in which the process's input went quiet for longer than its deadline.
    pub stale_input_episodes: u64,
    /// 1 while the input is quiet (stale) now.
    pub input_stale: u8,
    pub _pad2: [u8; 7],
}

/// Up to this many processes in a [`HealthReport`].
pub const MAX_SUPERVISED: usize = 8;

/// What the watchdog knows of one supervised process, [`ServiceHealth::state`].
#[repr(u8)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ServiceState {
    /// Started, no heartbeat from this process yet.
    #[default]
    Starting = 0,
    /// Running and heartbeating.
    Running = 1,
    /// Exited; waiting out its restart backoff.
    Restarting = 2,
    /// Its heartbeat is overdue although the process is still there (hung or starved).
    Silent = 3,
    /// It died more often than its restart limit allows; the watchdog no longer restarts it.
    GivenUp = 4,
}

impl ServiceState {
    pub const ALL: [ServiceState; 5] = [
        ServiceState::Starting,
        ServiceState::Running,
        ServiceState::Restarting,
        ServiceState::Silent,
        ServiceState::GivenUp,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ServiceState::Starting => "starting",
            ServiceState::Running => "running",
            ServiceState::Restarting => "restarting",
            ServiceState::Silent => "silent",
            ServiceState::GivenUp => "given-up",
        }
    }

    pub fn from_u8(v: u8) -> Option<Self> {
        Self::ALL.get(v as usize).copied()
    }
}

/// One process in a [`HealthReport`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::ServiceHealth")]
pub struct ServiceHealth {
    /// [`ServiceKind`] as u8.
    pub service: u8,
    /// [`ServiceState`] as u8.
    pub state: u8,
    /// 1 when the process's last heartbeat said its input is quiet (stale).
    pub input_stale: u8,
    pub _pad: [u8; 1],
    /// Process id (0 while restarting).
    pub pid: u32,
    /// Restarts since the watchdog started.
    pub restarts: u32,
    /// Age of the last heartbeat, ms; `u32::MAX` when none has arrived.
    pub heartbeat_age_ms: u32,
    /// Samples per second on the process's output topic over the last report period (NaN for a
    /// process without one).
    pub output_rate_hz: f32,
    pub _pad2: [u8; 4],
}

/// The watchdog's view of every process, published a few times a second on
/// [`names::HEALTH`]; `rins status` prints it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::HealthReport")]
pub struct HealthReport {
    pub version: u16,
    /// Entries of [`HealthReport::services`] in use.
    pub count: u8,
    pub _pad: [u8; 5],
    /// CLOCK_MONOTONIC ns when the report was made.
    pub now_ns: u64,
    /// Time since the watchdog started, ms.
    pub uptime_ms: u64,
    pub services: [ServiceHealth; MAX_SUPERVISED],
}
