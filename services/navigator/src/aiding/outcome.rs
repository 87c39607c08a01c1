//! What became of one aiding reading handed to the navigator.

use crate::ekf::UpdateOutcome;

/// What became of one aiding reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AidingOutcome {
    /// The filter took it (accepted or gated out: see the outcome).
    Update(UpdateOutcome),
    /// Kept for later: before alignment (the first baro height, the alignment heading).
    Stored,
    /// The first reading after an outage: the state was re-set from it (baro) or it was applied
    /// without the innovation gate (mag).
    Readmitted,
    /// Not used: aiding disabled, a bad reading, too old, rate limit, outside stance for HUPT.
    Skipped,
    /// Persistently rejected while the reading itself is sound: the filter's state was re-set
    /// from it (altitude from the baro, heading from the magnetometer), see [`crate::integrity`].
    Reset,
}
