//! Service names: the one place where topics are named.

/// Raw IMU frames ([`crate::RawImu`]), from acquisition.
pub const RAW_IMU: &str = "rins/raw/imu";
/// Raw barometer samples ([`crate::RawBaro`]), from acquisition.
pub const RAW_BARO: &str = "rins/raw/baro";
/// Raw magnetometer samples ([`crate::RawMag`]), from acquisition.
pub const RAW_MAG: &str = "rins/raw/mag";
/// Raw auxiliary (foot-pressure) samples ([`crate::RawAux`]), from acquisition.
pub const RAW_AUX: &str = "rins/raw/aux";
/// GNSS receiver epochs ([`crate::GnssFix`]), from the `gnss` service.
pub const GNSS: &str = "rins/gnss";
/// Fused body rate and specific force ([`crate::FusedImu`]), from fusion.
pub const FUSED_IMU: &str = "rins/fused/imu";
/// Barometric altitude ([`crate::Altitude`]), from the altimeter.
pub const ALTITUDE: &str = "rins/altitude";
/// The navigation solution ([`crate::NavState`]) of navigator lane 0, the primary.
pub const NAV_STATE: &str = "rins/nav/state";
/// Output topic of each navigator lane: lane 0 (primary) publishes on [`NAV_STATE`], so a
/// single-lane deployment needs nothing else; lane 1 is the hot standby. Consumers that want the
/// contiguous stream read both through the runtime's lane selector.
pub const NAV_LANES: [&str; 2] = [NAV_STATE, "rins/nav/state/standby"];
/// The simulator's ground truth ([`crate::Truth`]).
pub const TRUTH: &str = "rins/sim/truth";
/// Each process's once-a-second heartbeat with its counters ([`crate::Health`]).
pub const HEARTBEAT: &str = "rins/heartbeat";
/// The watchdog's report on every process ([`crate::HealthReport`]).
pub const HEALTH: &str = "rins/health";
/// Commands to the simulator (fault injection, [`crate::SimControl`]).
pub const SIM_CONTROL: &str = "rins/control/sim";
/// Fault commands the simulator handled, with the device time they took effect
/// ([`crate::FaultApplied`]).
pub const SIM_FAULT_APPLIED: &str = "rins/sim/fault";
/// Commands to fusion (re-admission of excluded channels, [`crate::FusionControl`]).
pub const FUSION_CONTROL: &str = "rins/control/fusion";
/// Fusion's answers to [`FUSION_CONTROL`] requests ([`crate::FusionReply`]).
pub const FUSION_REPLY: &str = "rins/control/fusion/reply";

/// Every published topic, with the short name `rins echo` accepts.
pub const TOPICS: [(&str, &str); 11] = [
    ("raw-imu", RAW_IMU),
    ("raw-baro", RAW_BARO),
    ("raw-mag", RAW_MAG),
    ("raw-aux", RAW_AUX),
    ("gnss", GNSS),
    ("fused-imu", FUSED_IMU),
    ("altitude", ALTITUDE),
    ("nav", NAV_STATE),
    ("truth", TRUTH),
    ("heartbeat", HEARTBEAT),
    ("health", HEALTH),
];
