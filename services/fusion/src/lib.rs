//! Redundancy fusion: turns the raw counts of N skewed single-axis gyros and accelerometers into a
//! body rate and specific force by weighted least squares over the configured sensor geometry.
//!
//! - [`geometry`]: sensitive-axis layouts (pyramid or explicit axes) and their noise figures.
//! - [`calibration`]: ADC counts to SI units per channel.
//! - [`wls`]: precomputed weighted least-squares solver for one active channel set.
//! - [`fuser`]: the gyro and accelerometer sides together, driven by the channel-valid mask.

pub mod calibration;
pub mod error;
pub mod fuser;
pub mod geometry;
mod linalg;
pub mod service;
pub mod wls;

pub use calibration::{Calibration, ChannelCalibration};
pub use error::ConfigError;
pub use fuser::{ChannelNoise, Fused, FusionConfig, ImuFuser, NoiseConfig, PerSensor};
pub use geometry::{Geometry, GeometryConfig};
pub use wls::{WlsError, WlsSolver};
