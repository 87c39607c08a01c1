//! Offline evaluation of the navigation chain, without IPC: the product's pure libraries run
//! in-process.
//!
//! - [`mc`]: Monte Carlo comparison of the redundant skewed block with an orthogonal triad built
//!   from the same sensors, with and without a dead gyro channel.
//! - [`fault_sweep`]: one fault per run injected into the configured chain in flight: detection,
//!   isolation, and the attitude error while the navigator's integrity said ok.
//! - [`gnss_captures`]: the GNSS decoder on real receivers' captures, against gpsd's decode of
//!   the same bytes.
//! - [`fdi`]: fault detection and isolation on the real quadrotor recordings (false alarms, and
//!   faults injected into the data).
//! - [`data`]: where each recorded data set is published and how it becomes the layout read here.
//! - [`datasets`]: loaders of recorded data sets (the four-IMU quadrotor flights).
//! - [`integrity_tally`]: the share of a recording the navigator judged ok, degraded, invalid.
//! - [`import`]: the public recordings as rins's own (raw IMU counts, truth, configuration).
//! - [`installation`]: relative rotation between IMUs from paired rate vectors (Wahba's problem).
//! - [`quadrotor_nav`]: free-inertial roll, pitch and height on the quadrotor recordings, each unit
//!   alone and the units fused.
//! - [`stats`]: mean, 2σ and RMS helpers.

pub mod data;
pub mod datasets;
pub mod fault_sweep;
pub mod fdi;
pub mod foot;
pub mod gnss_captures;
pub mod import;
pub mod installation;
pub mod integrity_tally;
pub mod leave_one_out;
pub mod mc;
pub mod parallel;
pub mod quadrotor_ahrs;
pub mod quadrotor_gnss;
pub mod quadrotor_nav;
pub mod stats;
mod trial_rows;
