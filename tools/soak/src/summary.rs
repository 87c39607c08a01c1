//! What a soak measured: the JSON summary it prints at the end.

use serde::Serialize;

use crate::fault_ledger::KindFigures;

/// What a soak measured: the JSON summary it prints at the end.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SoakSummary {
    /// Time from the first navigation sample to the end of the fault loop, minutes (less than
    /// asked when interrupted).
    pub minutes: f64,
    /// SIGKILLs sent (the `kill` faults).
    pub kills: u64,
    /// Restarts the watchdog made (from its summary): one per kill and per hang.
    pub restarts: u64,
    /// Navigation samples received through the lane selector.
    pub nav_samples: u64,
    /// Frames with no navigation output (gaps in the frame sequence of the `nav` topic).
    pub lost_nav_samples: u64,
    /// Longest wall-clock interval between two navigation samples, ms.
    pub max_gap_ms: f64,
    /// Samples after the first navigating one that were aligning again (a lane that could not
    /// recover its solution).
    pub not_navigating_samples: u64,
    /// Lane changes of the selector.
    pub lane_switches: u64,
    /// Samples the selector took from the other lane to fill a hole in the one it follows.
    pub lane_filled: u64,
    /// Faults put off because the pipeline had not recovered from the previous one yet.
    pub faults_deferred: u64,
    /// Per kind asked for: count, targets, navigation samples lost and longest gap while its
    /// faults lasted, failed and unrecovered faults.
    pub faults: std::collections::BTreeMap<&'static str, KindFigures>,
    /// Shared-memory entries left after the pipeline stopped (from the watchdog's summary).
    pub shm_leaked: u64,
}
