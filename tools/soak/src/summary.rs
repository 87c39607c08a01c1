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
    /// The deployment profile that ran, `shared` or `dedicated` (from the watchdog's summary).
    pub profile: String,
    /// Why (from the watchdog's summary).
    pub profile_reason: String,
}

impl SoakSummary {
    /// The summary as text for a person: the run, the navigation output, then one line per fault
    /// kind.
    pub fn to_text(&self) -> String {
        let mut out = format!(
            "soak: {:.1} min, {} kills, {} restarts, {} faults deferred, {} shared-memory entries left\n",
            self.minutes, self.kills, self.restarts, self.faults_deferred, self.shm_leaked
        );
        if !self.profile.is_empty() {
            out.push_str(&format!(
                "profile: {} — {}\n",
                self.profile, self.profile_reason
            ));
        }
        out.push_str(&format!(
            "navigation: {} samples, {} lost, longest gap {:.1} ms, {} not navigating, {} lane switches, {} filled from the other lane\n",
            self.nav_samples,
            self.lost_nav_samples,
            self.max_gap_ms,
            self.not_navigating_samples,
            self.lane_switches,
            self.lane_filled
        ));
        for (kind, f) in &self.faults {
            let targets: Vec<String> = f.targets.iter().map(|(t, n)| format!("{t} ×{n}")).collect();
            out.push_str(&format!(
                "  {kind}: {} faults ({}), {} samples lost, longest gap {:.1} ms, {} failed, {} unrecovered\n",
                f.count,
                if targets.is_empty() { "none".to_string() } else { targets.join(", ") },
                f.lost_nav_samples,
                f.max_gap_ms,
                f.failed,
                f.unrecovered
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_names_every_figure_and_each_kind() {
        let mut summary = SoakSummary {
            minutes: 2.0,
            kills: 3,
            restarts: 3,
            nav_samples: 120_000,
            lost_nav_samples: 7,
            profile: "shared".into(),
            profile_reason: "auto: 2 usable CPUs, 2 free; dedicated needs 4: shared".into(),
            ..SoakSummary::default()
        };
        let mut kill = KindFigures {
            count: 3,
            lost_nav_samples: 7,
            ..KindFigures::default()
        };
        kill.targets.insert("fusion".into(), 2);
        kill.targets.insert("altimeter".into(), 1);
        summary.faults.insert("kill", kill);
        let text = summary.to_text();
        assert!(
            text.starts_with("soak: 2.0 min, 3 kills, 3 restarts"),
            "{text}"
        );
        assert!(text.contains("120000 samples, 7 lost"), "{text}");
        assert!(
            text.contains(
                "\nprofile: shared — auto: 2 usable CPUs, 2 free; dedicated needs 4: shared\n"
            ),
            "{text}"
        );
        assert!(
            text.contains("  kill: 3 faults (altimeter ×1, fusion ×2), 7 samples lost"),
            "{text}"
        );
    }
}
