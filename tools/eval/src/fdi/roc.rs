//! The cross-validated receiver operating characteristic: for each false-alarm probability of
//! the sweep, the other settings chosen leave-one-flight-out, and the held-out flights' false
//! alarms per flight hour against the detection rate of each fault kind.

use serde::Serialize;

use super::candidates::{DetectorSetting, FALSE_ALARM_PROBABILITIES};
use super::cross_validation::leave_one_out;
use super::faults::FaultKind;
use super::table::{FlightOutcome, PreparedFlight};

/// Detection of one fault kind at one point of the curve.
#[derive(Debug, Clone, Serialize)]
pub struct KindDetection {
    /// Fault kind (`bias 5σ`, `ramp 2σ/s`, …).
    pub fault: String,
    /// Runs injected (both types, every channel, every flight).
    pub injected: usize,
    /// Runs detected.
    pub detected: usize,
    /// `detected / injected`.
    pub rate: f64,
}

/// One point of one configuration's curve.
#[derive(Debug, Clone, Serialize)]
pub struct RocPoint {
    /// The configuration.
    pub configuration: &'static str,
    /// The swept false-alarm probability per sample.
    pub false_alarm_probability: f64,
    /// False-alarm episodes on the held-out flights.
    pub false_alarms: usize,
    /// Those per flight hour of the configuration's flights.
    pub false_alarms_per_hour: f64,
    /// Detection per fault kind on the held-out flights.
    pub detection: Vec<KindDetection>,
}

/// Sums the held-out outcomes `table[f][chosen[i]]` of `flights` into per-kind detections.
pub(crate) fn detections(
    table: &[Vec<FlightOutcome>],
    flights: &[usize],
    chosen: &[usize],
    faults: &[FaultKind],
) -> (usize, Vec<KindDetection>) {
    let mut fa = 0;
    let mut det: Vec<KindDetection> = faults
        .iter()
        .map(|k| KindDetection {
            fault: k.name(),
            injected: 0,
            detected: 0,
            rate: 0.0,
        })
        .collect();
    for (&f, &s) in flights.iter().zip(chosen) {
        let o = &table[f][s];
        fa += o.false_alarm_episodes();
        for (i, t) in o.tallies.iter().enumerate() {
            let d = &mut det[i % faults.len()];
            d.injected += t.faults_injected;
            d.detected += t.detected;
        }
    }
    for d in &mut det {
        d.rate = if d.injected == 0 {
            0.0
        } else {
            d.detected as f64 / d.injected as f64
        };
    }
    (fa, det)
}

/// The curve of one configuration (its `flights`, indices into `table` and `prepared`).
pub(crate) fn curve(
    configuration: &'static str,
    table: &[Vec<FlightOutcome>],
    prepared: &[PreparedFlight],
    flights: &[usize],
    settings: &[DetectorSetting],
    faults: &[FaultKind],
) -> Vec<RocPoint> {
    let hours: f64 = flights.iter().map(|&f| prepared[f].seconds()).sum::<f64>() / 3600.0;
    FALSE_ALARM_PROBABILITIES
        .iter()
        .map(|&p| {
            let candidates: Vec<usize> = (0..settings.len())
                .filter(|&s| settings[s].false_alarm_probability == p)
                .collect();
            let fallback = candidates[candidates.len() / 2];
            let chosen = leave_one_out(table, flights, &candidates, faults, fallback);
            let (false_alarms, detection) = detections(table, flights, &chosen, faults);
            RocPoint {
                configuration,
                false_alarm_probability: p,
                false_alarms,
                false_alarms_per_hour: if hours > 0.0 {
                    false_alarms as f64 / hours
                } else {
                    0.0
                },
                detection,
            }
        })
        .collect()
}

/// Mean detection rate of the subtle kinds (neither channel-health faults nor the largest step)
/// at a point: the tie-break between points with equally few false alarms.
fn subtle_rate(point: &RocPoint, faults: &[FaultKind]) -> f64 {
    let largest = FaultKind::largest_bias(faults);
    let rates: Vec<f64> = point
        .detection
        .iter()
        .zip(faults)
        .filter(|(_, k)| !k.is_health() && **k != FaultKind::Bias(largest))
        .map(|(d, _)| d.rate)
        .collect();
    rates.iter().sum::<f64>() / rates.len().max(1) as f64
}

/// The operating point read off the cross-validated curve: the fewest false alarms per hour,
/// then the best detection of the subtle faults, then the more sensitive probability.
pub(crate) fn operating_probability(points: &[RocPoint], faults: &[FaultKind]) -> Option<f64> {
    let mut best: Option<&RocPoint> = None;
    for p in points {
        let better = match best {
            None => true,
            Some(b) => {
                p.false_alarms < b.false_alarms
                    || (p.false_alarms == b.false_alarms
                        && subtle_rate(p, faults) > subtle_rate(b, faults))
            }
        };
        if better {
            best = Some(p);
        }
    }
    best.map(|p| p.false_alarm_probability)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(p: f64, fa: usize, rates: [f64; 3]) -> RocPoint {
        RocPoint {
            configuration: "pyramid4",
            false_alarm_probability: p,
            false_alarms: fa,
            false_alarms_per_hour: fa as f64,
            detection: rates
                .iter()
                .map(|&rate| KindDetection {
                    fault: String::new(),
                    injected: 10,
                    detected: (rate * 10.0) as usize,
                    rate,
                })
                .collect(),
        }
    }

    #[test]
    fn the_operating_point_has_the_fewest_alarms_then_the_best_subtle_detection() {
        let faults = [FaultKind::Dead, FaultKind::Bias(20.0), FaultKind::Bias(5.0)];
        let points = [
            point(1e-6, 2, [1.0, 1.0, 0.9]),
            point(1e-8, 0, [1.0, 1.0, 0.6]),
            point(1e-10, 0, [1.0, 1.0, 0.7]),
            point(1e-12, 0, [1.0, 1.0, 0.5]),
        ];
        assert_eq!(operating_probability(&points, &faults), Some(1e-10));
    }
}
