//! MAVLink 2 messages from the navigation solution: what an on-board INS streams to an autopilot or a
//! ground station (attitude, global and local position, odometry with its covariance), built by pure
//! functions from the rins payloads, so that a sender around them stays thin.
//!
//! - [`local_frame`]: the local NED frame the local position and odometry are expressed in.
//! - [`attitude`]: the ATTITUDE_QUATERNION message.
//! - [`position`]: the GLOBAL_POSITION_INT and LOCAL_POSITION_NED messages.
//! - [`odometry`]: the ODOMETRY message with the covariance diagonal, the reset counter and the quality;
//!   [`autopilot`]: its frames and fields as PX4 or ArduPilot takes them; [`origin`]: the local
//!   frame's origin and its SET_GPS_GLOBAL_ORIGIN announcement.
//! - [`heartbeat`]: the HEARTBEAT message of the on-board profile and of the bench display profile.
//! - [`sys_status`]: the SYS_STATUS message with the bits of what rins has (gyro, accelerometer,
//!   AHRS; magnetometer, barometer and GPS when configured) and their health.
//! - [`status_text`]: the STATUSTEXT messages of channel exclusions, returns, lane switches and
//!   restarts; [`events`] finds them in the inputs.
//! - [`highres_imu`], [`vibration`]: the fused IMU and how much it shakes.
//! - [`timesync`], [`command`]: what rins answers on the link (TIMESYNC, a channel re-admission);
//!   [`command_gate`]: from whom it takes commands and how fast it answers them; [`signing`]: the
//!   MAVLink 2 signing key, signing and verification.
//! - [`stream`]: all of it as one state machine paced by [`rate_gate`]; [`link`] moves the messages
//!   to the network on its own threads, [`serial_link`] to and from a serial port (both frame what
//!   they send alike and act alike on what they receive, and count it in one
//!   [`link::LinkCounters`]); [`service`] is the process around them, [`config`] its `[mavlink]`
//!   table and [`endpoint`] its addresses; [`pipeline_cpu`] measures the pipeline's load for
//!   SYS_STATUS.
//!
//! Every message carries the measurement's time, not the send time: the receive time of the serial
//! frame the solution comes from, on the avionics computer's CLOCK_MONOTONIC (time since boot).

pub mod attitude;
pub mod autopilot;
pub mod command;
pub mod command_gate;
pub mod config;
pub mod endpoint;
pub mod events;
pub mod heartbeat;
pub mod highres_imu;
mod inbound;
pub mod link;
mod link_counters;
pub mod odometry;
pub mod origin;
pub mod pipeline_cpu;
pub mod position;
pub use rins_runtime::rate_gate;
pub mod serial_link;
pub mod service;
pub mod signing;
mod speaker;
pub mod status_text;
pub mod stream;
pub mod sys_status;
pub mod timesync;
pub mod vibration;

/// The local NED frame, shared with the other tools through `rins-earth`.
pub use rins_earth::local_frame;

pub use mavlink::dialects::common as dialect;

use ipc_types::NavState;

/// Time of the measurement behind `nav`, µs since boot (CLOCK_MONOTONIC).
pub fn time_usec(nav: &NavState) -> u64 {
    nav.header.origin_rx_ns / 1_000
}

/// [`time_usec`] in ms, wrapped as MAVLink's 32-bit `time_boot_ms` wraps (every 49.7 days).
pub fn time_boot_ms(nav: &NavState) -> u32 {
    (nav.header.origin_rx_ns / 1_000_000) as u32
}
