//! The navigator's aiding sources, one file each: its settings seen through the shared
//! `AidingSensor` trait (which sources the profile uses, which can go stale) and the updates it
//! makes to the filter, with what it keeps between readings; and the booking of every update for
//! the staleness and integrity records.

pub(crate) mod baro;
pub(crate) mod booking;
pub(crate) mod gnss;
pub(crate) mod gnss_state;
pub(crate) mod mag;
pub(crate) mod navigator_booking;
pub mod outcome;
pub(crate) mod source;
pub(crate) mod zupt;
