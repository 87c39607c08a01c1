//! Navigator core: static alignment, quaternion strapdown mechanisation, the error-state EKF and its
//! aiding (baro height, magnetometer heading, zero-velocity updates, tilt from the specific force,
//! GNSS position and velocity).
//!
//! Pure functions and small structs, no I/O. Frames: NED navigation, FRD body; quaternions rotate
//! body → NED (Hamilton, scalar first); SI units inside, degrees only in [`NavigatorConfig`].

pub mod aided_config;
pub mod aiding;
pub mod alignment;
pub mod attitude;
pub mod attitude_recovery;
mod checks;
pub mod config;
pub mod consumer_origin;
pub mod ekf;
pub mod force_delay;
pub mod force_window;
mod held_inputs;
mod imu_step;
pub mod inertial_core;
pub mod integrity;
pub mod lanes;
pub mod mag_calibration;
pub mod mechanisation;
pub mod navigator;
pub mod service;
pub mod smoother;
pub mod stance;
pub mod start;
pub mod state_history;
pub mod takeover;
pub mod unisolated_fault;

pub use alignment::{AlignConfig, AlignError, Alignment, StaticAligner};
pub use config::{ConfigError, NavigatorConfig};
pub use mechanisation::{ImuBias, NominalState, StepOutcome, Strapdown, StrapdownConfig};
pub use navigator::{NavOutput, Navigator};
