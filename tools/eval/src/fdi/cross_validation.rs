//! Leave-one-flight-out choice of the detector setting, per configuration.
//!
//! For each flight, the setting is chosen on the *other* flights of the same configuration by one
//! fixed rule, and the flight is scored with it. The rule, in order:
//! 1. the setting must meet the detection targets on the training flights — at least
//!    [`HEALTH_TARGET`] of the channel-health faults (dead, stuck, saturated) and
//!    [`BIAS_TARGET`] of the largest bias steps detected;
//! 2. then the fewest false-alarm episodes on the training flights;
//! 3. then a safety factor: the fault-free checks (parity statistic, noise-outlier level) must
//!    have stayed below [`MARGIN`] of their thresholds on every training flight. A setting that
//!    only just stayed quiet on the training flights is the one that alarms on the next flight:
//!    choosing on detection alone tripled the held-out false alarms;
//! 4. among settings with that margin, the most detections of the subtle faults (the smaller
//!    steps, the ramp, the noise increase); among settings without it, the largest margin;
//! 5. then the first in grid order.
//!
//! A configuration seen on one flight only has nothing to learn from: that flight is scored with
//! the grid's middle setting and counted as such.

use super::faults::FaultKind;
use super::table::FlightOutcome;

/// Fraction of channel-health faults a setting must detect on the training flights.
pub const HEALTH_TARGET: f64 = 0.99;
/// Fraction of the largest bias steps a setting must detect on the training flights.
pub const BIAS_TARGET: f64 = 0.95;
/// Largest fraction of its threshold a fault-free check may reach on the training flights for
/// the setting to count as having margin: a factor two of headroom, the usual engineering
/// factor between the largest fault-free statistic seen and the threshold.
pub const MARGIN: f64 = 0.5;

/// How good a setting was on a set of flights (the rule's keys).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Score {
    meets_targets: bool,
    false_alarms: usize,
    /// Largest parity statistic over its threshold on any training flight, either type.
    peak_ratio: f64,
    subtle_detected: usize,
}

impl Score {
    /// Whether `self` ranks above `other` by the rule of the module docs.
    fn better_than(&self, other: &Score) -> bool {
        use std::cmp::Ordering::{Greater, Less};
        let key = |s: &Score| (s.meets_targets, std::cmp::Reverse(s.false_alarms));
        match key(self).cmp(&key(other)) {
            Greater => return true,
            Less => return false,
            _ => {}
        }
        let (mine, theirs) = (self.peak_ratio <= MARGIN, other.peak_ratio <= MARGIN);
        if mine != theirs {
            return mine;
        }
        if mine && self.subtle_detected != other.subtle_detected {
            return self.subtle_detected > other.subtle_detected;
        }
        self.peak_ratio < other.peak_ratio
    }
}

fn score(
    table: &[Vec<FlightOutcome>],
    flights: &[usize],
    setting: usize,
    faults: &[FaultKind],
) -> Score {
    let largest_bias = FaultKind::largest_bias(faults);
    let (mut health, mut health_n, mut bias, mut bias_n) = (0, 0, 0, 0);
    let (mut false_alarms, mut subtle_detected) = (0, 0);
    let mut peak_ratio: f64 = 0.0;
    for &f in flights {
        let o = &table[f][setting];
        false_alarms += o.false_alarm_episodes();
        peak_ratio = peak_ratio.max(o.peak_ratio());
        for (i, t) in o.tallies.iter().enumerate() {
            let kind = faults[i % faults.len()];
            if kind.is_health() {
                health += t.detected;
                health_n += t.faults_injected;
            } else if kind == FaultKind::Bias(largest_bias) {
                bias += t.detected;
                bias_n += t.faults_injected;
            } else {
                subtle_detected += t.detected;
            }
        }
    }
    let rate = |a: usize, n: usize| if n == 0 { 1.0 } else { a as f64 / n as f64 };
    Score {
        meets_targets: rate(health, health_n) >= HEALTH_TARGET && rate(bias, bias_n) >= BIAS_TARGET,
        false_alarms,
        peak_ratio,
        subtle_detected,
    }
}

/// The best of `candidates` (setting indices) on `flights` by the rule of the module docs.
pub(crate) fn choose(
    table: &[Vec<FlightOutcome>],
    flights: &[usize],
    candidates: &[usize],
    faults: &[FaultKind],
) -> Option<usize> {
    let mut best: Option<(usize, Score)> = None;
    for &c in candidates {
        let s = score(table, flights, c, faults);
        let better = match &best {
            None => true,
            Some((_, b)) => s.better_than(b),
        };
        if better {
            best = Some((c, s));
        }
    }
    best.map(|(c, _)| c)
}

/// For each of `flights` (indices into `table`, one configuration), the setting chosen on the
/// others among `candidates`; `fallback` when there is no other flight.
pub(crate) fn leave_one_out(
    table: &[Vec<FlightOutcome>],
    flights: &[usize],
    candidates: &[usize],
    faults: &[FaultKind],
    fallback: usize,
) -> Vec<usize> {
    flights
        .iter()
        .map(|&f| {
            let train: Vec<usize> = flights.iter().copied().filter(|&g| g != f).collect();
            if train.is_empty() {
                fallback
            } else {
                choose(table, &train, candidates, faults).unwrap_or(fallback)
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fdi::tally::Tally;

    /// A flight outcome with `fa` false alarms and, per fault kind of [`kinds`], `detected` of
    /// 10 injected.
    fn outcome(fa: usize, detected: [usize; 3]) -> FlightOutcome {
        with_peak(fa, detected, 0.5)
    }

    fn with_peak(fa: usize, detected: [usize; 3], peak: f64) -> FlightOutcome {
        FlightOutcome {
            false_alarms: [fa, 0],
            false_alarm_samples: [0; 2],
            over_range: [0; 2],
            max_t_ratio: [peak, 0.0],
            max_noise_peak: [0.0; 2],
            alarm_starts: Vec::new(),
            tallies: detected
                .iter()
                .map(|&d| Tally {
                    faults_injected: 10,
                    detected: d,
                    ..Tally::default()
                })
                .collect(),
        }
    }

    fn kinds() -> Vec<FaultKind> {
        vec![FaultKind::Dead, FaultKind::Bias(20.0), FaultKind::Bias(5.0)]
    }

    #[test]
    fn the_rule_prefers_targets_then_fewer_alarms_then_subtle_detections() {
        // Settings: 0 misses dead faults; 1 has an alarm; 2 and 3 are clean, 3 finds more 5σ.
        let row = vec![
            outcome(0, [5, 10, 10]),
            outcome(1, [10, 10, 10]),
            outcome(0, [10, 10, 2]),
            outcome(0, [10, 10, 6]),
        ];
        let table = vec![row.clone(), row];
        assert_eq!(choose(&table, &[0, 1], &[0, 1, 2, 3], &kinds()), Some(3));
        assert_eq!(choose(&table, &[0, 1], &[0, 1, 2], &kinds()), Some(2));
        assert_eq!(choose(&table, &[0, 1], &[0, 1], &kinds()), Some(1));
        // Between clean settings: the one with margin wins over more subtle detections; with
        // margin both, the more sensitive one; without, the larger margin.
        let row = vec![
            with_peak(0, [10, 10, 9], 0.9),
            with_peak(0, [10, 10, 2], 0.4),
            with_peak(0, [10, 10, 3], 0.45),
            with_peak(0, [10, 10, 9], 0.7),
        ];
        let table = vec![row.clone(), row];
        assert_eq!(choose(&table, &[0, 1], &[0, 1], &kinds()), Some(1));
        assert_eq!(choose(&table, &[0, 1], &[0, 1, 2], &kinds()), Some(2));
        assert_eq!(choose(&table, &[0, 1], &[0, 3], &kinds()), Some(3));
    }

    #[test]
    fn a_flight_never_chooses_on_itself() {
        // Flight 0 alone would pick setting 0 (it is clean there); the other two flights have
        // alarms with setting 0 and none with setting 1, so flight 0 is scored with setting 1.
        let table = vec![
            vec![outcome(0, [10, 10, 9]), outcome(3, [10, 10, 1])],
            vec![outcome(2, [10, 10, 9]), outcome(0, [10, 10, 1])],
            vec![outcome(2, [10, 10, 9]), outcome(0, [10, 10, 1])],
        ];
        let chosen = leave_one_out(&table, &[0, 1, 2], &[0, 1], &kinds(), 0);
        assert_eq!(chosen[0], 1);
        // Alone in its configuration: the fallback.
        assert_eq!(leave_one_out(&table, &[2], &[0, 1], &kinds(), 1), vec![1]);
    }
}
