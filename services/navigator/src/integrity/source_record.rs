//! What the integrity monitor keeps of one aiding source: the NIS of its last accepted updates
//! and its current run of rejections.

use super::config::MAX_NIS_WINDOW;

/// Consistency record of one aiding source.
#[derive(Debug, Clone, Copy)]
pub(super) struct SourceRecord {
    /// d²/m of the last accepted updates (ring).
    pub(super) nis: [f64; MAX_NIS_WINDOW],
    pub(super) next: usize,
    pub(super) len: usize,
    /// Device time of the first rejection of the current run (`None` after an acceptance).
    pub(super) rejected_since_us: Option<u64>,
    /// Updates in the current run of rejections.
    pub(super) rejected_run: u32,
    /// Accepted since the last invalid episode or reset.
    pub(super) confirmed: bool,
    /// Updates tried at all.
    pub(super) attempts: u64,
}

impl Default for SourceRecord {
    fn default() -> Self {
        Self {
            nis: [0.0; MAX_NIS_WINDOW],
            next: 0,
            len: 0,
            rejected_since_us: None,
            rejected_run: 0,
            confirmed: false,
            attempts: 0,
        }
    }
}

/// Rejected updates in a row that make a source inconsistent (degraded); persistent (a reset, or
/// invalid when every source is) once the run has also lasted `rejection_persist_s`.
pub(super) const MIN_REJECTED_RUN: u32 = 3;

impl SourceRecord {
    pub(super) fn mean_nis(&self) -> Option<f64> {
        (self.len > 0).then(|| self.nis[..self.len].iter().sum::<f64>() / self.len as f64)
    }

    pub(super) fn persistently_rejected(&self, now_us: u64, persist_us: u64) -> bool {
        self.rejected_since_us.is_some_and(|since| {
            self.rejected_run >= MIN_REJECTED_RUN && now_us.saturating_sub(since) >= persist_us
        })
    }
}
