//! Barometric altimeter: ISA pressure-altitude and a constant-velocity Kalman filter that turns
//! barometer samples into height, vertical speed and their variances.
//!
//! - [`isa`]: ISA troposphere pressure ↔ altitude for a given QNH.
//! - [`estimator`]: [`AltitudeEstimator`] with plausibility checks and gap resets.

pub mod error;
pub mod estimator;
pub mod isa;
pub mod service;

pub use error::ConfigError;
pub use estimator::{AltimeterConfig, AltitudeEstimator, AltitudeOutput};
