//! Device simulator core: a deterministic truth trajectory, per-channel sensor error models and the
//! frame generator that emulates the redundant sensor block. Pure: no I/O, no clocks, no globals.
//!
//! The Earth is modelled as non-rotating with constant gravity [`GRAVITY_MPS2`]; see [`trajectory`].

pub mod config;
pub mod device_fault;
pub mod error;
pub mod fault_command;
pub mod fault_schedule;
pub mod outage;
pub mod sensor_model;
pub mod serial_line;
pub mod service;
pub mod sim_command;
pub mod simulator;
pub mod trajectory;

pub use config::{EarthFieldConfig, SimConfig};
pub use error::SimError;
pub use sensor_model::SensorModelConfig;
pub use sensor_model::fault::{ChannelFault, InertialSensor};
pub use simulator::{Simulator, TickOutput, TruthSample};
pub use trajectory::{Scenario, Trajectory, TrajectoryStart, TruthState};

/// Standard gravity, m/s² (g_n = [0, 0, +g] in NED).
pub const GRAVITY_MPS2: f64 = 9.80665;
