//! Booking an aiding update: the device time of the last accepted one per source (the solution's
//! age and the sources' staleness) and the integrity monitor's record of the source.

use crate::ekf::{AidingSource, UpdateOutcome};
use crate::integrity::IntegrityMonitor;

/// Books one update of `source` at `t_us` that measured `dof` components; `result` is what the
/// filter made of it. Takes the two records, not the navigator, so that the inertial core can
/// book while it holds its filter.
pub(crate) fn record_update(
    last_accepted_us: &mut [Option<u64>; AidingSource::COUNT],
    integrity: &mut IntegrityMonitor,
    source: AidingSource,
    t_us: u64,
    result: UpdateOutcome,
    dof: u32,
) {
    if result.is_accepted() {
        last_accepted_us[source as usize] = Some(t_us);
    }
    integrity.on_update(source, t_us, result, dof);
}

/// Books a reset of the filter from `source` at `t_us`: it counts as an accepted update.
pub(crate) fn record_reset(
    last_accepted_us: &mut [Option<u64>; AidingSource::COUNT],
    integrity: &mut IntegrityMonitor,
    source: AidingSource,
    t_us: u64,
) {
    last_accepted_us[source as usize] = Some(t_us);
    integrity.on_reset(source, t_us);
}
