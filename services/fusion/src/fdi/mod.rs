//! Fault detection, isolation and reconfiguration (FDI) of the redundant channels.
//!
//! - [`parity`]: parity basis V (faer SVD), whitening, test statistic, GLT scores.
//! - [`chi2`]: χ² tail and quantile for the thresholds.
//! - [`persistence`]: k-of-n declaration and its false-alarm arithmetic.
//! - [`isolation`]: GLT isolation over the persistence window.
//! - [`mean_shift`]: the windowed mean of the parity, for biases below the per-sample test.
//! - [`channel_health`]: missing, saturated, stuck and noisy channels from counts and values.
//! - [`stationary`]: stationary detector and the per-channel reference for N = 4 isolation.
//! - [`offset`]: the learnt parity offset (channel biases left by calibration).
//! - [`noise_estimate`]: the adaptive parity noise covariance.
//! - [`recovery`]: re-test of latched exclusions when a sensor type has lost its solution.
//! - [`probation`]: the tests a channel re-admitted by command passes before it rejoins.
//! - [`monitor`]: all of the above for one sensor type, with latched exclusions.
//! - [`report`]: per-channel states, reasons and state-change events.
//! - [`config`]: the `[fusion.fdi]` table.

pub mod channel_health;
pub mod chi2;
pub mod config;
pub mod dense;
pub mod isolation;
pub mod mean_shift;
pub mod monitor;
pub mod noise_estimate;
pub mod offset;
pub mod parity;
pub mod persistence;
pub mod probation;
pub mod recovery;
pub mod report;
pub mod stationary;

use crate::geometry::MAX_CHANNELS;

/// Largest parity dimension: N − 3 for N = 16.
pub const MAX_PARITY: usize = MAX_CHANNELS - 3;

pub use config::{FdiConfig, FdiSettings, ParityNoise, ReadmitPolicy};
pub use monitor::{MonitorInput, ReadmitError, SensorEstimate, SensorMonitor};
pub use parity::{ParityError, ParitySpace};
pub use report::{ChannelEvent, ChannelEvents, MAX_EVENTS, SensorStatus};
