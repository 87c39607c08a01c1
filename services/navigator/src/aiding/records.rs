//! What the navigator records of every aiding source, whichever it is: the device time of its
//! last reading (its staleness) and of its last accepted update (the solution's age), and the
//! booking of each update in the integrity monitor's record of the source.

use crate::ekf::{AidingSource, UpdateOutcome};
use crate::integrity::IntegrityMonitor;

/// The readings and accepted updates of every source, per [`AidingSource`].
#[derive(Debug, Clone)]
pub(crate) struct SourceRecords {
    /// Device time of the last accepted update, µs.
    last_accepted_us: [Option<u64>; AidingSource::COUNT],
    /// Device time of the last valid reading, µs.
    last_reading_us: [Option<u64>; AidingSource::COUNT],
    /// Device time navigation started, µs.
    navigating_since_us: Option<u64>,
    /// The profile uses the source and its silence is an outage.
    watched: [bool; AidingSource::COUNT],
    /// A watched source silent for longer than this is stale, s.
    stale_after_s: f64,
}

impl SourceRecords {
    /// Empty records; `watched` marks the sources whose silence for `stale_after_s` is an outage.
    pub(crate) fn new(watched: [bool; AidingSource::COUNT], stale_after_s: f64) -> Self {
        Self {
            last_accepted_us: [None; AidingSource::COUNT],
            last_reading_us: [None; AidingSource::COUNT],
            navigating_since_us: None,
            watched,
            stale_after_s,
        }
    }

    /// Navigation (re)started at device time `since_us`: a source that never reported is counted
    /// silent from then on.
    pub(crate) fn start_navigating(&mut self, since_us: Option<u64>) {
        self.navigating_since_us = since_us;
    }

    /// True when `source` is watched but has gone quiet at device time `now_us`: no valid reading
    /// for `stale_after_s` (counted from the start of navigation when it never reported). False
    /// before navigation starts.
    pub(crate) fn is_stale(&self, source: AidingSource, now_us: Option<u64>) -> bool {
        let (Some(now), Some(since)) = (now_us, self.navigating_since_us) else {
            return false;
        };
        let last = self.last_reading_us[source as usize]
            .unwrap_or(since)
            .max(since);
        self.watched[source as usize] && now.saturating_sub(last) as f64 * 1e-6 > self.stale_after_s
    }

    /// A valid reading of `source` at `t_us`.
    pub(crate) fn note_reading(&mut self, source: AidingSource, t_us: u64) {
        self.last_reading_us[source as usize] = Some(t_us);
    }

    /// An update of `source` at `t_us` the filter took, not booked with the integrity monitor.
    pub(crate) fn note_accepted(&mut self, source: AidingSource, t_us: u64) {
        self.last_accepted_us[source as usize] = Some(t_us);
    }

    /// Device time of the last accepted update from `source`, µs.
    pub(crate) fn last_accepted_us(&self, source: AidingSource) -> Option<u64> {
        self.last_accepted_us[source as usize]
    }

    /// Books one update of `source` at `t_us` that measured `dof` components; `result` is what
    /// the filter made of it.
    pub(crate) fn book_update(
        &mut self,
        integrity: &mut IntegrityMonitor,
        source: AidingSource,
        t_us: u64,
        result: UpdateOutcome,
        dof: u32,
    ) {
        if result.is_accepted() {
            self.note_accepted(source, t_us);
        }
        integrity.on_update(source, t_us, result, dof);
    }

    /// Books a reset of the filter from `source` at `t_us`: it counts as an accepted update.
    pub(crate) fn book_reset(
        &mut self,
        integrity: &mut IntegrityMonitor,
        source: AidingSource,
        t_us: u64,
    ) {
        self.note_accepted(source, t_us);
        integrity.on_reset(source, t_us);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn watching_baro() -> SourceRecords {
        let mut watched = [false; AidingSource::COUNT];
        watched[AidingSource::Baro as usize] = true;
        SourceRecords::new(watched, 1.0)
    }

    #[test]
    fn a_watched_source_is_stale_once_silent_for_the_timeout() {
        let mut r = watching_baro();
        // Not navigating yet: nothing is stale.
        assert!(!r.is_stale(AidingSource::Baro, Some(5_000_000)));
        r.start_navigating(Some(1_000_000));
        // Never reported: silent since navigation started.
        assert!(!r.is_stale(AidingSource::Baro, Some(2_000_000)));
        assert!(r.is_stale(AidingSource::Baro, Some(2_000_001)));
        r.note_reading(AidingSource::Baro, 1_800_000);
        assert!(!r.is_stale(AidingSource::Baro, Some(2_800_000)));
        assert!(r.is_stale(AidingSource::Baro, Some(2_800_001)));
        // A source not watched never goes stale.
        assert!(!r.is_stale(AidingSource::Zupt, Some(60_000_000)));
    }

    #[test]
    fn only_accepted_updates_and_resets_date_the_source() {
        let mut r = watching_baro();
        let mut integrity = IntegrityMonitor::new(
            crate::integrity::IntegrityConfig::default(),
            [true; AidingSource::COUNT],
            [0; AidingSource::COUNT],
        );
        let gated = UpdateOutcome::Rejected { d2: 100.0 };
        r.book_update(&mut integrity, AidingSource::Baro, 10, gated, 1);
        assert_eq!(r.last_accepted_us(AidingSource::Baro), None);
        let taken = UpdateOutcome::Accepted { d2: 1.0 };
        r.book_update(&mut integrity, AidingSource::Baro, 20, taken, 1);
        assert_eq!(r.last_accepted_us(AidingSource::Baro), Some(20));
        r.book_reset(&mut integrity, AidingSource::Baro, 30);
        assert_eq!(r.last_accepted_us(AidingSource::Baro), Some(30));
    }
}
