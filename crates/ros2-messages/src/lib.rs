//! The ROS 2 messages rins publishes beyond its host, as ROS 2 nodes read them: the definitions
//! (field for field those of `nav_msgs`, `sensor_msgs`, `geometry_msgs`, `std_msgs` and
//! `builtin_interfaces`), their CDR encoding (the serialization rmw implementations put on the
//! wire, little endian), and ROS's frame conventions (REP 103: ENU for the world, FLU for the body;
//! REP 105: the pose in a local world frame, the twist in the body frame).
//!
//! rins's own conventions are NED and FRD ([`ipc_types::NavState`]); [`frames`] converts, and
//! [`from_rins`] builds the messages from rins's payloads.

pub mod decode;
pub mod diagnostics;
pub mod encode;
pub mod frames;
pub mod from_rins;
pub mod messages;

pub use decode::{DecodeError, decode};
pub use diagnostics::{DiagnosticArray, DiagnosticStatus, KeyValue};
pub use encode::encode;
pub use messages::{Imu, NavSatFix, Odometry};
