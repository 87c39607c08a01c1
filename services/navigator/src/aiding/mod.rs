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
//! implements `AidingSensor`, `source.rs`), its state, and its update taking an `AidingContext`;
//! then one line in each list of [`crate::aided_config::AidedConfig`] (`sensors()` and
//! `sources()`, beside its settings field, also in [`crate::NavigatorConfig`]), a field in
//! `AidingSources` (`sources.rs`), the core's entry point that hands it its readings, and the
//! service's subscription to its topic.

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
