//! Barometric altimeter: ISA pressure-altitude and a constant-velocity Kalman filter that turns
//! barometer samples into height, vertical speed and their variances.
//!
//! - ISA troposphere pressure ↔ altitude for a given QNH: `rins_earth::isa`.
//! - [`estimator`]: [`AltitudeEstimator`] with plausibility checks and gap resets.

pub mod error;
pub mod estimator;
pub mod service;

pub use error::ConfigError;
pub use estimator::{AltimeterConfig, AltitudeEstimator, AltitudeOutput};
