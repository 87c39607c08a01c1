//! Device simulator: a deterministic truth trajectory, per-channel sensor error models and the frame
//! generator that emulates the redundant sensor block — pure, no I/O, no clocks, no globals — and,
//! around them, the process: the simulated serial line on a pseudo-terminal ([`serial_line`]), the
//! fault commands it takes and the truth it publishes, one tick per IMU period on the runtime's
//! paced loop ([`service`]).
//!
//! The Earth is modelled as non-rotating with constant standard gravity
//! ([`rins_earth::STANDARD_GRAVITY`]); see [`trajectory`].

pub mod calibration_config;
pub mod config;
mod device;
pub mod device_fault;
pub mod error;
pub mod fault_command;
pub mod fault_parse_error;
pub mod fault_schedule;
pub mod gnss_config;
pub mod gnss_receiver;
pub mod outage;
pub mod sensor_model;
pub mod serial_line;
pub mod service;
pub mod sim_command;
pub mod simulator;
mod slow_sensor;
mod slow_sensor_list;
mod slow_sensors;
mod streaming;
pub mod trajectory;

pub use calibration_config::CalibrationConfig;
pub use config::{EarthFieldConfig, SimConfig};
pub use error::SimError;
pub use fault_parse_error::FaultParseError;
pub use sensor_model::SensorModelConfig;
pub use sensor_model::fault::{ChannelFault, InertialSensor};
pub use simulator::{Simulator, TickOutput, TruthSample};
pub use trajectory::{Scenario, Trajectory, TrajectoryStart, TruthState};
