//! Commands to the pipeline and their answers: fault injection into the simulator
//! ([`SimControl`], answered by [`FaultApplied`]) and re-admission of an excluded channel by
//! fusion ([`FusionControl`], answered by [`FusionReply`]).

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

wire_enum! {
    /// Which redundant sensor type a command addresses.
    pub enum SensorType: u8 {
        /// The gyros (body rate).
        Gyro = 0 => "gyro",
        /// The accelerometers (specific force).
        Accel = 1 => "accel",
    }
}

wire_enum! {
    /// Fault the simulator applies to one channel ([`SimControl::fault`]).
    pub enum SimFault: u8 {
        /// Remove any fault from the channel.
        Clear = 0 => "clear",
        /// The channel stops: flagged invalid.
        Dead = 1 => "dead",
        /// The channel repeats its last value.
        Stuck = 2 => "stuck",
        /// A bias step of `param` (SI units: rad/s or m/s²).
        BiasStep = 3 => "bias",
        /// A bias ramp of `param` per second.
        Ramp = 4 => "ramp",
        /// White noise multiplied by `param`.
        Noise = 5 => "noise",
        /// The channel reads full scale.
        Saturate = 6 => "saturate",
        /// The channel drops out for the first half of every `param` seconds.
        Intermittent = 7 => "intermittent",
        /// The whole serial line goes away for `param` seconds, like a pulled cable: the device's
        /// port vanishes and comes back as a new one. Addresses no channel: [`SimControl::sensor`]
        /// is [`SimControl::WHOLE_DEVICE`] and `channel` 0.
        Disconnect = 8 => "disconnect",
        /// The GNSS receiver loses its fix for `param` seconds (0: until cleared); it goes on
        /// sending epochs without a position. Addresses [`SimControl::GNSS_RECEIVER`].
        GnssOutage = 9 => "gnss-outage",
        /// The GNSS position jumps `param` metres north and stays there until cleared.
        GnssJump = 10 => "gnss-jump",
        /// The GNSS receiver repeats its last fix for `param` seconds (0: until cleared).
        GnssFreeze = 11 => "gnss-freeze",
        /// The GNSS position drifts north at `param` m/s from now on (a spoofer pulling it away
        /// slowly), until cleared; the reported velocity is left true.
        GnssDrift = 12 => "gnss-drift",
    }
}

/// Command to the simulator: apply a fault to one channel ("killing a sensor"). Sent by
/// `rins inject` on [`crate::names::SIM_CONTROL`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::SimControl")]
pub struct SimControl {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// [`SensorType`] as u8, or [`SimControl::WHOLE_DEVICE`].
    pub sensor: u8,
    /// Channel index within the sensor type, from 0.
    pub channel: u8,
    /// [`SimFault`] as u8.
    pub fault: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 3],
    /// Fault parameter, see [`SimFault`].
    pub param: f64,
}

impl SimControl {
    /// [`SimControl::sensor`] of a fault of the whole device ([`SimFault::Disconnect`]): no
    /// [`SensorType`], so that consumers of channel faults pass it by.
    pub const WHOLE_DEVICE: u8 = u8::MAX;
    /// [`SimControl::sensor`] of a fault of the simulated GNSS receiver (the `Gnss*` faults, and
    /// [`SimFault::Clear`] to end them); `channel` 0.
    pub const GNSS_RECEIVER: u8 = u8::MAX - 1;
}

wire_enum! {
    /// What the simulator did with one [`SimControl`] command ([`FaultApplied::outcome`]).
    pub enum FaultOutcome: u8 {
        /// The fault (or its clearing) took effect at [`FaultApplied::device_time_us`].
        Applied = 0 => "applied",
        /// The command named a sensor type or fault kind the simulator does not know.
        UnknownCommand = 1 => "unknown-command",
        /// The sensor block has no such channel.
        NoSuchChannel = 2 => "no-such-channel",
        /// The fault parameter is out of range (e.g. a noise factor below 1).
        InvalidParameter = 3 => "invalid-parameter",
    }
}

/// Published by the simulator for every fault command it handled (scheduled or received on
/// [`crate::names::SIM_CONTROL`]), so that detection and isolation delays can be measured in
/// device time.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FaultApplied")]
pub struct FaultApplied {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// [`SensorType`] as u8, as given in the command.
    pub sensor: u8,
    /// Channel index, as given in the command.
    pub channel: u8,
    /// [`SimFault`] as u8, as given in the command.
    pub fault: u8,
    /// [`FaultOutcome`] as u8.
    pub outcome: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 2],
    /// Device time of the first IMU sample the fault affects, µs since the simulator started (the
    /// time base of [`crate::Header::origin_device_time_us`]).
    pub device_time_us: u64,
    /// The command's parameter, see [`SimFault`].
    pub param: f64,
}

/// Command to fusion: return an excluded channel to service (exclusions latch otherwise). Sent by
/// `rins readmit` on [`crate::names::FUSION_CONTROL`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FusionControl")]
pub struct FusionControl {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// [`SensorType`] as u8.
    pub sensor: u8,
    /// Channel index within the sensor type, from 0.
    pub channel: u8,
    /// Chosen by the sender and returned in the [`FusionReply`], so that a sender knows its
    /// answer among others'.
    pub request_id: u32,
}

wire_enum! {
    /// What fusion did with one [`FusionControl`] request ([`FusionReply::outcome`]).
    pub enum ReadmitOutcome: u8 {
        /// The channel is back in the solution and stayed clean over the probation period.
        Readmitted = 0 => "readmitted",
        /// The channel was not excluded: nothing to do.
        NotExcluded = 1 => "not-excluded",
        /// The sensor block has no such channel.
        NoSuchChannel = 2 => "no-such-channel",
        /// The request could not be read (payload version, unknown sensor type).
        BadRequest = 3 => "bad-request",
        /// The channel was excluded again during the probation period: the fault is still
        /// present ([`FusionReply::reason`] says which test found it).
        FaultStillPresent = 4 => "fault-still-present",
        /// Too many re-admissions are on probation at once: nothing was done, ask again.
        Busy = 5 => "busy",
    }
}

/// Fusion's answer to one [`FusionControl`] request, on [`crate::names::FUSION_REPLY`].
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::FusionReply")]
pub struct FusionReply {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// [`SensorType`] as u8, as given in the request.
    pub sensor: u8,
    /// Channel index, as given in the request.
    pub channel: u8,
    /// The request's [`FusionControl::request_id`].
    pub request_id: u32,
    /// [`ReadmitOutcome`] as u8.
    pub outcome: u8,
    /// [`crate::FaultReason`] as u8: why the channel is excluded again (or was never excluded:
    /// `none`).
    pub reason: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 2],
    /// Process id of the fusion process that answers.
    pub pid: u32,
}
