//! How much of a recording the navigator judged usable: the integrity verdict of every sample after
//! alignment, counted. On a recording whose solution is known to be good against its truth, time
//! spent degraded or invalid is a false integrity alarm.

use ipc_types::{Integrity, integrity_reason};
use serde::Serialize;

/// Samples per integrity level and every reason seen.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct IntegrityTally {
    samples: [u64; 3],
    reasons: u32,
}

/// What a report carries of a [`IntegrityTally`].
#[derive(Debug, Clone, Serialize)]
pub struct IntegritySummary {
    /// Fraction of the samples judged ok, 0..=1.
    pub ok_fraction: f64,
    /// Fraction of the samples judged degraded, 0..=1.
    pub degraded_fraction: f64,
    /// Fraction of the samples judged invalid, 0..=1.
    pub invalid_fraction: f64,
    /// Every reason seen, comma-separated names.
    pub reasons: String,
}

impl IntegrityTally {
    /// Counts one sample's integrity level and its reason bits (`ipc_types::integrity_reason`).
    pub fn push(&mut self, (level, reasons): (Integrity, u32)) {
        self.samples[level as usize] += 1;
        self.reasons |= reasons;
    }

    /// The fractions per level (all 0 when nothing was counted) and the names of every reason seen.
    pub fn summary(&self) -> IntegritySummary {
        let total = self.samples.iter().sum::<u64>().max(1) as f64;
        let fraction = |level: Integrity| self.samples[level as usize] as f64 / total;
        IntegritySummary {
            ok_fraction: fraction(Integrity::Ok),
            degraded_fraction: fraction(Integrity::Degraded),
            invalid_fraction: fraction(Integrity::Invalid),
            reasons: integrity_reason::describe(self.reasons),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_and_reasons() {
        let mut t = IntegrityTally::default();
        for _ in 0..3 {
            t.push((Integrity::Ok, 0));
        }
        t.push((Integrity::Degraded, integrity_reason::RECOVERING));
        let s = t.summary();
        assert_eq!(
            (s.ok_fraction, s.degraded_fraction, s.invalid_fraction),
            (0.75, 0.25, 0.0)
        );
        assert_eq!(s.reasons, "recovering");
    }
}
