//! Loaders of recorded data sets.

mod csv;
pub mod error;
pub mod quadrotor;

pub use error::DatasetError;
