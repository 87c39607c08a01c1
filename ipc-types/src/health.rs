//! Supervision: each process's heartbeat with its counters ([`Health`]) and the watchdog's view of
//! every process ([`HealthReport`]).

use iceoryx2::prelude::ZeroCopySend;
use serde::Serialize;

use crate::{FusedImu, MAX_CHANNELS};

wire_enum! {
    /// Which process a [`Health`] message speaks for; the name is the process's service name.
    pub enum ServiceKind: u8 {
        /// The device simulator, `rins sim`.
        Simulator = 0 => "sim",
        /// Serial acquisition.
        Acquisition = 1 => "acquisition",
        /// Redundancy fusion and fault detection.
        Fusion = 2 => "fusion",
        /// Barometric altimeter.
        Altimeter = 3 => "altimeter",
        /// The primary navigator lane (lane 0).
        Navigator = 4 => "navigator",
        /// The watchdog, `rins up`.
        Watchdog = 5 => "watchdog",
        /// The hot-standby navigator lane (lane 1).
        NavigatorStandby = 6 => "navigator-standby",
        /// The MAVLink output, when enabled.
        Mavlink = 7 => "mavlink",
        /// GNSS receiver acquisition, when a receiver is configured.
        Gnss = 8 => "gnss",
        /// The Zenoh bridge (ROS 2 topics beyond the host), when enabled.
        Bridge = 9 => "bridge",
    }
}

impl ServiceKind {
    /// The navigator process of each lane, [`crate::NavState::lane`].
    pub const NAVIGATOR_LANES: [ServiceKind; 2] =
        [ServiceKind::Navigator, ServiceKind::NavigatorStandby];
}

/// Periodic heartbeat and counters of one process, published once a second by every process on
/// [`crate::names::HEARTBEAT`]. Counters count since the process started.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::Health")]
pub struct Health {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// [`ServiceKind`] as u8.
    pub service: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 1],
    /// Process id of the sender.
    pub pid: u32,
    /// CLOCK_MONOTONIC ns when this heartbeat was published.
    pub now_ns: u64,
    /// Messages taken in since start.
    pub received: u64,
    /// Messages published since start.
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
    /// not counted in `lost` (acquisition); aiding readings that arrived after their place in the
    /// IMU stream had passed (navigator); ticks run a period or more behind their time, caught up
    /// (simulator).
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
    /// Bytes read from the input device (acquisition).
    pub bytes_received: u64,
    /// Serial frames that decoded with a valid CRC and sane content (acquisition), published or
    /// withheld as duplicate or late.
    pub valid_frames: u64,
    /// 1 while the input is quiet (stale) now.
    pub input_stale: u8,
    /// [`LinkError`] as u8: why the last undecodable bytes could not be decoded (acquisition).
    pub last_decode_error: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad2: [u8; 6],
}

wire_enum! {
    /// Why the last bytes acquisition could not decode were refused ([`Health::last_decode_error`],
    /// [`LinkReport::last_decode_error`]).
    #[derive(Default)]
    pub enum LinkError: u8 {
        /// Nothing undecodable seen yet.
        #[default]
        None = 0 => "none",
        /// Bytes without the frame sync word (wrong baud rate, wrong protocol, line noise).
        NoSync = 1 => "no-sync",
        /// A frame whose type byte names no known frame type.
        UnknownFrameType = 2 => "unknown-frame-type",
        /// A frame whose length disagrees with its type.
        BadLength = 3 => "bad-length",
        /// A frame whose CRC does not match.
        CrcMismatch = 4 => "crc-mismatch",
        /// A frame with a valid CRC and insane content (channel counts, samples out of range).
        BadContent = 5 => "bad-content",
    }
}

/// Up to this many processes in a [`HealthReport`].
pub const MAX_SUPERVISED: usize = 10;

wire_enum! {
    /// What the watchdog knows of one supervised process, [`ServiceHealth::state`].
    #[derive(Default)]
    pub enum ServiceState: u8 {
        /// Started, no heartbeat from this process yet.
        #[default]
        Starting = 0 => "starting",
        /// Running and heartbeating.
        Running = 1 => "running",
        /// Exited; waiting out its restart backoff.
        Restarting = 2 => "restarting",
        /// Its heartbeat is overdue although the process is still there (hung or starved).
        Silent = 3 => "silent",
        /// It died more often than its restart limit allows; the watchdog no longer restarts it.
        GivenUp = 4 => "given-up",
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
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
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
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad2: [u8; 4],
}

/// The watchdog's view of every process, published a few times a second on
/// [`crate::names::HEALTH`]; `rins status` prints it.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::HealthReport")]
pub struct HealthReport {
    /// Layout version, [`crate::PAYLOAD_VERSION`].
    pub version: u16,
    /// Entries of [`HealthReport::services`] in use.
    pub count: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 5],
    /// CLOCK_MONOTONIC ns when the report was made.
    pub now_ns: u64,
    /// Time since the watchdog started, ms.
    pub uptime_ms: u64,
    /// One entry per supervised process; the first [`HealthReport::count`] are in use.
    pub services: [ServiceHealth; MAX_SUPERVISED],
    /// The serial line, from acquisition's last heartbeat.
    pub link: LinkReport,
    /// The redundant channels, from fusion's latest output.
    pub redundancy: RedundancyReport,
    /// The navigation solution in use, from the lane the consumers follow.
    pub nav: NavReport,
    /// The GNSS receiver's line, from the `gnss` service's last report (not heard without one).
    pub gnss: crate::GnssLinkReport,
}

/// The serial line as acquisition last reported it ([`HealthReport::link`]). Counters count
/// since the acquisition process started.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::LinkReport")]
pub struct LinkReport {
    /// 1 once a heartbeat of acquisition has been seen; the rest is meaningless while 0.
    pub heard: u8,
    /// [`LinkError`] as u8: why the last undecodable bytes were refused.
    pub last_decode_error: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 6],
    /// Bytes read from the device.
    pub bytes_received: u64,
    /// Frames with a valid CRC and sane content.
    pub valid_frames: u64,
    /// Bytes skipped because they did not belong to a valid frame.
    pub discarded_bytes: u64,
    /// Frames with a bad CRC.
    pub crc_errors: u64,
    /// Frames with a valid CRC and malformed content.
    pub malformed: u64,
    /// Times the device was reopened.
    pub reconnects: u64,
}

/// The redundant channels as fusion last judged them ([`HealthReport::redundancy`]); the same
/// fields as [`crate::FusedImu`] carries.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::RedundancyReport")]
pub struct RedundancyReport {
    /// 1 once a fused sample has been seen; the rest is meaningless while 0.
    pub heard: u8,
    /// Gyro channels fitted.
    pub n_gyro: u8,
    /// Accelerometer channels fitted.
    pub n_accel: u8,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad: [u8; 1],
    /// [`crate::fused_flags`] of the latest fused sample.
    pub flags: u32,
    /// Per gyro channel, [`crate::ChannelState`] as u8.
    pub gyro_state: [u8; MAX_CHANNELS],
    /// Per accelerometer channel, [`crate::ChannelState`] as u8.
    pub accel_state: [u8; MAX_CHANNELS],
    /// Per gyro channel, [`crate::FaultReason`] as u8.
    pub gyro_reason: [u8; MAX_CHANNELS],
    /// Per accelerometer channel, [`crate::FaultReason`] as u8.
    pub accel_reason: [u8; MAX_CHANNELS],
    /// Gyro parity test statistic (0 without a parity space).
    pub gyro_test_statistic: f32,
    /// Accelerometer parity test statistic (0 without a parity space).
    pub accel_test_statistic: f32,
    /// Age of the fused sample when the report was made, ms.
    pub age_ms: u32,
    /// Zero; makes the padding explicit so that the layout has no hidden bytes.
    pub _pad2: [u8; 4],
}

impl Default for RedundancyReport {
    /// No fused sample heard: the channels as a default [`FusedImu`] has them (none fitted, every
    /// one absent, no fault reason, no test statistic).
    fn default() -> Self {
        let none = FusedImu::default();
        Self {
            heard: 0,
            n_gyro: none.n_gyro,
            n_accel: none.n_accel,
            _pad: [0; 1],
            flags: none.flags,
            gyro_state: none.gyro_state,
            accel_state: none.accel_state,
            gyro_reason: none.gyro_reason,
            accel_reason: none.accel_reason,
            gyro_test_statistic: none.gyro_test_statistic,
            accel_test_statistic: none.accel_test_statistic,
            age_ms: 0,
            _pad2: [0; 4],
        }
    }
}

/// The navigation solution in use as the watchdog last saw it ([`HealthReport::nav`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, ZeroCopySend)]
#[type_name("rins::NavReport")]
pub struct NavReport {
    /// 1 once a navigation sample has been seen; the rest is meaningless while 0.
    pub heard: u8,
    /// [`crate::NavMode`] as u8.
    pub mode: u8,
    /// The lane that produced it, [`crate::NavState::lane`].
    pub lane: u8,
    /// [`crate::Integrity`] as u8.
    pub integrity: u8,
    /// [`crate::aiding`] bits.
    pub aiding: u32,
    /// [`crate::integrity_reason`] bits.
    pub integrity_reasons: u32,
    /// Age of the navigation sample when the report was made, ms.
    pub age_ms: u32,
}
