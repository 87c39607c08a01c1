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
//! implements `AidingSensor`, `source.rs`: its bucket with its inconsistency reason, and the range
//! check of its settings; one `stream_aiding_sensor!` does it for a source whose readings arrive
//! on a stream of their own), its state, and its update taking an `AidingContext`; then its line in
//! the table of `ipc_types::aiding` (its [`crate::ekf::AidingSource`], aiding bit and name), one
//! line in `aiding_sources!` (`sources.rs`, which makes its field of `AidingSources` and its
//! places in [`crate::aided_config::AidedConfig`]'s `sensors()` and `sources()`), and its
//! settings field in `AidedConfig` and in [`crate::NavigatorConfig`] (with its default and its
//! copy into `AidedConfig`). A source whose readings arrive on a topic of their own defines its
//! reading type (built from the topic's payload) and its `on_reading`, and takes one line in
//! `held_readings!` (`readings.rs`): that line makes its place in the hold queue, the navigator's
//! entry point and the service's subscription (the offline replay feeds it once its raw topic is
//! in the replay's list of raw samples).

pub mod airspeed;
pub mod baro;
pub(crate) mod context;
pub mod gnss;
pub mod hold;
pub mod mag;
pub mod mag_heading;
pub mod outcome;
pub mod readings;
pub(crate) mod records;
pub(crate) mod source;
pub(crate) mod sources;
pub mod tilt;
pub mod zupt;
