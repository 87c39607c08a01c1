//! What every aiding source tells the navigator's shared bookkeeping about itself: the bucket its
//! updates are booked under, whether the profile uses it, whether its silence is an outage, how
//! the navigator's output and integrity verdict name its buckets, and how its settings are checked.

use rins_runtime::config_error::ConfigError;

use crate::ekf::AidingSource;

/// How the navigator reports one bucket of updates (its aiding bit is its source's,
/// [`AidingSource::bit`]): the `ipc_types::integrity_reason` bit raised when its innovations are
/// inconsistent (0: its verdicts never count).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Bucket {
    /// The bucket.
    pub(crate) source: AidingSource,
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

    /// `(field, value)` of its settings' first out-of-range value.
    fn first_out_of_range(&self) -> Result<(), (&'static str, f64)>;

    /// Its settings' section (`navigator.<source>`), and what is in range there in words, for the
    /// error that names the first value out of range.
    fn section(&self) -> (&'static str, &'static str);

    /// Its settings' first out-of-range value, named within its section.
    fn validate(&self) -> Result<(), ConfigError> {
        let (section, range) = self.section();
        self.first_out_of_range()
            .map_err(|(field, value)| ConfigError::new(field, value, range).within(section))
    }
}

/// Implements [`AidingSensor`] for the settings of a source whose readings arrive on a stream of
/// their own (a silence is an outage), booked under one bucket, applied while the settings'
/// `enabled` field is set and range-checked by their `check()` method (`(field, value)` of the
/// first value out of range). Grammar, one invocation per settings type:
///
/// ```text
/// stream_aiding_sensor!(SettingsType => AidingSourceVariant, inconsistent: REASON_BIT,
///     section: "navigator.<source>", range: "what is in range, in words");
/// ```
macro_rules! stream_aiding_sensor {
    (
        $settings:ty => $source:ident,
        inconsistent: $reason:expr,
        section: $section:literal,
        range: $range:literal $(,)?
    ) => {
        impl $crate::aiding::source::AidingSensor for $settings {
            fn source(&self) -> $crate::ekf::AidingSource {
                $crate::ekf::AidingSource::$source
            }

            fn buckets(&self) -> &'static [$crate::aiding::source::Bucket] {
                &[$crate::aiding::source::Bucket {
                    source: $crate::ekf::AidingSource::$source,
                    inconsistent: $reason,
                }]
            }

            fn enabled(&self) -> bool {
                self.enabled
            }

            fn watched_for_staleness(&self) -> bool {
                true
            }

            fn first_out_of_range(&self) -> Result<(), (&'static str, f64)> {
                self.check()
            }

            fn section(&self) -> (&'static str, &'static str) {
                ($section, $range)
            }
        }
    };
}

pub(crate) use stream_aiding_sensor;
