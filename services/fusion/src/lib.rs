//! Redundancy fusion: turns the raw counts of N skewed single-axis gyros and accelerometers into a
//! body rate and specific force by weighted least squares over the configured sensor geometry.
//!
//! - [`geometry`]: sensitive-axis layouts (pyramid or explicit axes) and their noise figures.
//! - [`calibration`]: ADC counts to SI units per channel.
//! - [`wls`]: precomputed weighted least-squares solver for one active channel set.
//! - [`fdi`]: fault detection (parity, χ², channel health), isolation and reconfiguration.
//! - [`kalman`]: the optional Kalman fusion method over the same channel sets.
//! - [`rest_bias`]: per-channel gyro biases from a start-up window at rest.
//! - [`config`]: the `[fusion]` table and its checks.
//! - [`fuser`]: the gyro and accelerometer sides together, with their fault monitors.
//! - [`readmit_probation`]: the answer to a re-admission, once its probation has a verdict.

pub mod calibration;
pub mod capability;
pub mod config;
pub mod error;
pub mod fdi;
pub mod fuser;
pub mod geometry;
pub mod kalman;
mod linalg;
pub mod readmit_probation;
pub mod rest_bias;
pub mod service;
pub mod wls;

pub use calibration::{Calibration, ChannelCalibration};
pub use config::{ChannelNoise, FusionConfig, NoiseConfig, PerSensor};
pub use error::ConfigError;
pub use fdi::{ChannelEvent, ChannelEvents, FdiConfig, ParityNoise, ParitySpace, SensorStatus};
pub use fuser::{Fused, ImuFuser, ImuSample};
pub use geometry::{Geometry, GeometryConfig};
pub use kalman::{FusionMethod, KalmanConfig};
pub use rest_bias::RestBiasState;
pub use wls::{WlsError, WlsSolver};
