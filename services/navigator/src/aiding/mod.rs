//! The navigator's aiding sources, one file (or folder) each, modelled on the aiding sources of
//! PX4's EKF2: a source owns its settings, what it keeps between readings (hold-offs, rate
//! limits, references, monitors), its gating and its reset policy. The inertial core lends it an
//! `AidingContext` (`context.rs`) for each reading: the filter or the aligner, the IMU stream's
//! time, stance and force, and the booking of its updates. Every update reaches the filter as one
//! linearised measurement ([`crate::ekf::Linearised`]) through
//! [`crate::ekf::ErrorStateEkf::apply`]. Readings that arrive on topics of their own wait in one
//! [`hold::Hold`] for their place in the IMU stream.
//!
//! Adding a source: one file here with its settings (a `[navigator.<source>]` section that
//! implements `AidingSensor`, `source.rs`: its bucket with its aiding bit and inconsistency
//! reason, and the check of its settings), its state, and its update taking an `AidingContext`;
//! then its `AidingSource` bucket ([`crate::ekf::AidingSource`]), one line in `aiding_sources!`
//! (`sources.rs`, which makes its field of `AidingSources` and its places in
//! [`crate::aided_config::AidedConfig`]'s `sensors()` and `sources()`), its settings field in
//! `AidedConfig` and in [`crate::NavigatorConfig`] (with its default and its copy into
//! `AidedConfig`), and, for readings on a topic of their own, the core's entry point that hands
//! it its readings, their place in the hold queue (`readings.rs`) and the service's subscription
//! to its topic.

pub mod airspeed;
pub mod baro;
pub(crate) mod context;
pub mod gnss;
pub mod hold;
pub(crate) mod mag;
pub mod mag_heading;
pub mod outcome;
pub mod readings;
pub(crate) mod records;
pub(crate) mod source;
pub(crate) mod sources;
pub mod tilt;
pub mod zupt;
