//! The soak's account of its faults, per kind: how many, on what, and what each cost the
//! navigation output. Faults come one at a time, so everything lost from one fault to the next
//! is charged to the first.

use std::collections::BTreeMap;
use std::time::Duration;

use serde::Serialize;

use super::fault_plan::FaultKind;

/// One kind's figures in the summary.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct KindFigures {
    /// Faults carried out.
    pub count: u64,
    /// Faults per target (`fusion`, `gyro2 stuck`, `device`).
    pub targets: BTreeMap<String, u64>,
    /// Navigation samples missing from the consumers' stream while this kind's faults lasted.
    pub lost_nav_samples: u64,
    /// Longest silence of the navigation output during this kind's faults, ms.
    pub max_gap_ms: f64,
    /// Faults that could not be carried out (the command failed; the message went to stderr).
    pub failed: u64,
    /// Faults after which the pipeline had not recovered within the soak's recovery limit.
    pub unrecovered: u64,
}

#[derive(Debug, Default)]
pub struct FaultLedger {
    kinds: BTreeMap<&'static str, KindFigures>,
    /// The fault being charged and the missing-sample count when it began.
    open: Option<(&'static str, u64)>,
}

impl FaultLedger {
    /// A ledger with a (zero) row for every kind asked for, so the summary lists each.
    pub fn new(kinds: &[FaultKind]) -> Self {
        Self {
            kinds: kinds
                .iter()
                .map(|k| (k.name(), KindFigures::default()))
                .collect(),
            open: None,
        }
    }

    /// A fault of `kind` on `target` begins; `missing` is the stream's missing-sample count now,
    /// `gap` the longest silence since the previous fault began (charged to that one).
    pub fn begin(&mut self, kind: FaultKind, target: String, missing: u64, gap: Duration) {
        self.close(missing, gap);
        let row = self.kinds.entry(kind.name()).or_default();
        row.count += 1;
        *row.targets.entry(target).or_default() += 1;
        self.open = Some((kind.name(), missing));
    }

    /// Charges what was lost since the open fault began to it (at the next fault and at the end).
    pub fn close(&mut self, missing: u64, gap: Duration) {
        if let Some((kind, at_start)) = self.open.take() {
            let row = self.kinds.entry(kind).or_default();
            row.lost_nav_samples += missing.saturating_sub(at_start);
            row.max_gap_ms = row.max_gap_ms.max(gap.as_secs_f64() * 1e3);
        }
    }

    /// The open fault could not be carried out.
    pub fn failed(&mut self) {
        if let Some((kind, _)) = self.open {
            self.kinds.entry(kind).or_default().failed += 1;
        }
    }

    /// The pipeline did not recover from the open fault in time.
    pub fn unrecovered(&mut self) {
        if let Some((kind, _)) = self.open {
            self.kinds.entry(kind).or_default().unrecovered += 1;
        }
    }

    pub fn count(&self, kind: FaultKind) -> u64 {
        self.kinds.get(kind.name()).map_or(0, |r| r.count)
    }

    pub fn figures(&self) -> &BTreeMap<&'static str, KindFigures> {
        &self.kinds
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: fn(u64) -> Duration = Duration::from_millis;

    #[test]
    fn losses_are_charged_to_the_fault_they_follow() {
        let mut l = FaultLedger::new(&[FaultKind::Kill, FaultKind::Hang, FaultKind::Disconnect]);
        // 2 lost before any fault: charged to none (the soak's total still counts them).
        l.begin(FaultKind::Kill, "fusion".into(), 2, MS(5));
        l.begin(FaultKind::Hang, "acquisition".into(), 2, MS(30));
        l.failed();
        l.begin(FaultKind::Kill, "fusion".into(), 2_902, MS(3_100));
        l.unrecovered();
        l.close(2_910, MS(40));
        let f = l.figures();
        assert_eq!(f["kill"].count, 2);
        assert_eq!(f["kill"].targets["fusion"], 2);
        assert_eq!(f["kill"].lost_nav_samples, 8);
        assert_eq!(f["kill"].max_gap_ms, 40.0);
        assert_eq!((f["kill"].failed, f["kill"].unrecovered), (0, 1));
        assert_eq!(f["hang"].lost_nav_samples, 2_900);
        assert_eq!(f["hang"].max_gap_ms, 3_100.0);
        assert_eq!((f["hang"].failed, f["hang"].unrecovered), (1, 0));
        // Asked for but never drawn: listed with zeros.
        assert_eq!(f["disconnect"], KindFigures::default());
        assert_eq!(l.count(FaultKind::Kill), 2);
        assert_eq!(l.count(FaultKind::Sensor), 0);
    }

    #[test]
    fn closing_twice_charges_once() {
        let mut l = FaultLedger::new(&[FaultKind::Kill]);
        l.begin(FaultKind::Kill, "navigator".into(), 0, MS(0));
        l.close(5, MS(10));
        l.close(9, MS(99));
        assert_eq!(l.figures()["kill"].lost_nav_samples, 5);
        assert_eq!(l.figures()["kill"].max_gap_ms, 10.0);
    }
}
