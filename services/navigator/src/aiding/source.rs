//! What every aiding source tells the navigator's shared bookkeeping about itself: the bucket its
//! updates are booked under, whether the profile uses it, and whether its silence is an outage.

use crate::ekf::AidingSource;

/// One aiding source's settings, as the navigator's shared bookkeeping sees them (which sources
/// the profile uses, which of them can go stale). Each source implements it beside its updates.
pub(crate) trait AidingSensor {
    /// The source its updates are booked under.
    fn source(&self) -> AidingSource;

    /// The profile applies its updates.
    fn enabled(&self) -> bool;

    /// Its readings arrive on a stream of their own, so that a silence longer than
    /// `stale_after_s` is an outage (pseudo-measurements made from the IMU samples themselves
    /// never go quiet).
    fn watched_for_staleness(&self) -> bool;

    /// Its rejections and silences count in the integrity verdict (see [`crate::integrity`]).
    fn judged_by_integrity(&self) -> bool {
        true
    }
}
