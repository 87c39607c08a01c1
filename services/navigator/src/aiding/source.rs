//! What every aiding source tells the navigator's shared bookkeeping about itself: the bucket its
//! updates are booked under, whether the profile uses it, whether its silence is an outage, how
//! the navigator's output and integrity verdict name its buckets, and how its settings are checked.

use rins_runtime::config_error::ConfigError;

use crate::ekf::AidingSource;

/// How the navigator reports one bucket of updates: the `ipc_types::aiding` bit that says it
/// aids the solution, and the `ipc_types::integrity_reason` bit raised when its innovations are
/// inconsistent (0: its verdicts never count).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Bucket {
    /// The bucket.
    pub(crate) source: AidingSource,
    /// Its aiding bit in the navigation state.
    pub(crate) aiding_bit: u32,
    /// Its reason bit when its innovations are inconsistent.
    pub(crate) inconsistent: u32,
}

/// One aiding source's settings, as the navigator's shared bookkeeping sees them (which sources
/// the profile uses, which of them can go stale, how they are reported). Each source implements
/// it beside its updates.
pub(crate) trait AidingSensor {
    /// The source its updates are booked under.
    fn source(&self) -> AidingSource;

    /// Every bucket its updates may be booked under, whatever the settings (each bucket is
    /// declared by exactly one source).
    fn buckets(&self) -> &'static [Bucket];

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

    /// Its settings' first out-of-range value, named within its `[navigator.<source>]` section.
    fn validate(&self) -> Result<(), ConfigError>;
}
