//! Navigator core: static alignment, quaternion strapdown mechanisation and baro height blend.
//!
//! Pure functions and small structs, no I/O. Frames: NED navigation, FRD body; quaternions rotate
//! body → NED (Hamilton, scalar first); SI units inside, degrees only in [`NavigatorConfig`].

pub mod aided;
pub mod alignment;
pub mod attitude;
pub mod baro_blend;
pub mod config;
pub mod earth;
pub mod ekf;
pub mod mag_calibration;
pub mod mechanisation;
pub mod navigator;
pub mod service;
pub mod stance;

pub use alignment::{AlignConfig, AlignError, Alignment, StaticAligner};
pub use baro_blend::{BaroBlend, BaroBlendConfig, BaroOutcome};
pub use config::{ConfigError, NavigatorConfig};
pub use mechanisation::{ImuBias, NominalState, StepOutcome, Strapdown, StrapdownConfig};
pub use navigator::{NavOutput, Navigator};
