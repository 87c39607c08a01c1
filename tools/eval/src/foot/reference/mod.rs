//! The peer's published method, as a reference estimator for `rins eval pyshoe|xio --method
//! reference`: the SHOE stance detector and a 9-state zero-velocity-aided error-state Kalman
//! filter (Skog, Händel, Nilsson and Rantakokko, "Zero-velocity detection — an algorithm
//! evaluation"; Wagstaff, Peretroukhin and Kelly, "Robust data-driven zero-velocity detection for
//! foot-mounted inertial navigation"), written from the papers' equations with the parameters of
//! the latter's evaluation: σ_a = 0.00098 m/s², σ_ω = 8.7266463e-5 rad/s, T = 1/200 s, W = 5.
//!
//! It is not the product's navigator: it exists so that the peer's method, run here with one
//! threshold for every trial, sits beside rins on the same metric and the same data.

pub mod shoe;
pub mod zupt_filter;

pub use shoe::{shoe_statistic, stance_below};
pub use zupt_filter::{ReferenceConfig, ReferenceRun, run_reference, run_with_statistic};
