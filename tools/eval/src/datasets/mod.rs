//! Loaders of recorded data sets.

mod csv;
pub mod error;
pub mod foot;
pub mod location;
pub mod pyshoe;
pub mod quadrotor;
pub mod xio;

pub use error::DatasetError;
pub use foot::{FootSample, FootTrial, PeerResult};
pub use location::{recording_set, recordings_dir};
