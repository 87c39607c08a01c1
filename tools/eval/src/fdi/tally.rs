//! Detection and isolation of injected faults, counted over fault runs, with the median and
//! largest delays.

use serde::Serialize;

use super::runs::Outcome;
use crate::datasets::quadrotor::IMU_RATE_HZ;

/// Detection and isolation of injected faults, counted. Delays are in faulty samples processed
/// until the fuser flagged (1 = on the first faulty sample); the median and maximum are filled in
/// by [`Tally::finish`] (`None` when nothing was detected or isolated).
#[derive(Debug, Clone, Default, Serialize)]
pub struct Tally {
    /// Fault runs counted.
    pub faults_injected: usize,
    /// Runs in which the fuser raised an alarm on the faulty type.
    pub detected: usize,
    /// Runs in which the fuser excluded a channel.
    pub isolated: usize,
    /// Runs in which the channel excluded was the faulty one.
    pub correctly_isolated: usize,
    /// Detection delay of each detected run, samples.
    #[serde(skip)]
    pub detection_delays: Vec<usize>,
    /// Isolation delay of each isolated run, samples.
    #[serde(skip)]
    pub isolation_delays: Vec<usize>,
    /// Median detection delay, samples.
    pub detection_delay_samples_p50: Option<f64>,
    /// Longest detection delay, samples.
    pub detection_delay_samples_max: Option<usize>,
    /// Median detection delay, ms at the data set's IMU rate.
    pub detection_delay_ms_p50: Option<f64>,
    /// Longest detection delay, ms.
    pub detection_delay_ms_max: Option<f64>,
    /// Median isolation delay, samples.
    pub isolation_delay_samples_p50: Option<f64>,
    /// Longest isolation delay, samples.
    pub isolation_delay_samples_max: Option<usize>,
    /// Median isolation delay, ms at the data set's IMU rate.
    pub isolation_delay_ms_p50: Option<f64>,
    /// Longest isolation delay, ms.
    pub isolation_delay_ms_max: Option<f64>,
}

fn median(v: &[usize]) -> Option<f64> {
    let mut s = v.to_vec();
    s.sort_unstable();
    let n = s.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => Some(s[n / 2] as f64),
        _ => Some((s[n / 2 - 1] + s[n / 2]) as f64 / 2.0),
    }
}

fn ms(samples: f64) -> f64 {
    samples * 1000.0 / IMU_RATE_HZ
}

impl Tally {
    /// Counts one fault run whose fault was injected into `channel`.
    pub fn add(&mut self, o: &Outcome, channel: usize) {
        self.faults_injected += 1;
        if let Some(d) = o.detected {
            self.detected += 1;
            self.detection_delays.push(d);
        }
        if let Some((d, x)) = o.isolated {
            self.isolated += 1;
            self.isolation_delays.push(d);
            self.correctly_isolated += usize::from(x == channel);
        }
    }

    /// Adds another tally's counts and delays (its medians and maxima are not carried: call
    /// [`Tally::finish`] after the last merge).
    pub fn merge(&mut self, other: &Tally) {
        self.faults_injected += other.faults_injected;
        self.detected += other.detected;
        self.isolated += other.isolated;
        self.correctly_isolated += other.correctly_isolated;
        self.detection_delays.extend(&other.detection_delays);
        self.isolation_delays.extend(&other.isolation_delays);
    }

    /// Computes the medians and maxima from the delays collected.
    pub fn finish(&mut self) {
        self.detection_delay_samples_p50 = median(&self.detection_delays);
        self.detection_delay_samples_max = self.detection_delays.iter().copied().max();
        self.detection_delay_ms_p50 = self.detection_delay_samples_p50.map(ms);
        self.detection_delay_ms_max = self.detection_delay_samples_max.map(|d| ms(d as f64));
        self.isolation_delay_samples_p50 = median(&self.isolation_delays);
        self.isolation_delay_samples_max = self.isolation_delays.iter().copied().max();
        self.isolation_delay_ms_p50 = self.isolation_delay_samples_p50.map(ms);
        self.isolation_delay_ms_max = self.isolation_delay_samples_max.map(|d| ms(d as f64));
    }
}
