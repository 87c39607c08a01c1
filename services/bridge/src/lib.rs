//! rins beyond the host: the navigation state, the fused IMU and the watchdog's report published
//! over Zenoh as ROS 2 messages, on the key expressions, with the attachments and the liveliness
//! tokens of rmw_zenoh (ROS 2's Zenoh middleware), so that ROS 2 nodes on other computers read
//! them with no bridge of their own, and rins's own tools read a deployment remotely.
//!
//! - [`config`]: `[zenoh]`; [`endpoint`]: its addresses; [`session_config`]: the Zenoh session's
//!   configuration from them.
//! - [`ros_graph`]: the key expressions and liveliness tokens; [`attachment`]: what each sample
//!   carries beside its CDR bytes.
//! - [`diagnostics`]: the watchdog's report as a `DiagnosticArray`.
//! - [`outbox`]: which samples are due (pure); [`network`]: the thread that puts them on Zenoh;
//!   [`service`]: the process around them.

pub mod attachment;
pub mod config;
pub mod diagnostics;
pub mod endpoint;
pub mod network;
pub mod outbox;
pub mod ros_graph;
pub mod service;
pub mod session_config;
