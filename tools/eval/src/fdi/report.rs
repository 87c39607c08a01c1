//! The evaluation's report: tallies, per-trial rows, and the text tables.

use std::path::PathBuf;

use serde::Serialize;

use super::NoiseFit;
use super::runs::Outcome;
use crate::datasets::quadrotor::{IMU_RATE_HZ, SkippedTrial, skipped_lines};

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

/// One configuration's tally for one sensor type and fault kind, over every trial.
#[derive(Debug, Clone, Serialize)]
pub struct FaultBreakdown {
    /// The configuration: `pyramid4` (four skewed channels, docs/design.md §4) or `stacked12` (the
    /// four units' triads stacked).
    pub configuration: &'static str,
    /// Sensor type faulted: `gyro` or `accel`.
    pub sensor: &'static str,
    /// Fault kind: `dead`, `stuck`, `bias Nσ` or `saturated`.
    pub fault: String,
    /// The runs' detection and isolation.
    #[serde(flatten)]
    pub tally: Tally,
}

/// One trial in one configuration: its fault-free run and the data's own figures.
#[derive(Debug, Clone, Serialize)]
pub struct TrialReport {
    /// The trial's name (`<group>/path_<N>`).
    pub trial: String,
    /// Rows of the trial after preparation.
    pub rows: usize,
    /// Length of the trial at the IMU rate, s.
    pub seconds: f64,
    /// The configuration: `pyramid4` (four skewed channels, docs/design.md §4) or `stacked12` (the
    /// four units' triads stacked).
    pub configuration: &'static str,
    /// Alarm episodes without any fault, gyro and accel.
    pub false_alarms: [usize; 2],
    /// Episodes of genuine over-range (channels Suspect, saturated), gyro and accel.
    pub over_range: [usize; 2],
    /// Samples in an alarmed state without any fault, gyro and accel.
    pub false_alarm_samples: [usize; 2],
    /// Each false alarm: when, why, and which unit's channel stood out in noise.
    pub alarm_episodes: Vec<super::AlarmEpisode>,
    /// Largest parity T / threshold after learning, gyro and accel.
    pub max_t_over_threshold: [f64; 2],
    /// Per-trial parity estimate of the channel σ, gyro rad/s and accel m/s².
    pub sigma_hat: [f64; 2],
    /// Largest relative bias removed, gyro rad/s and accel m/s².
    pub max_relative_bias: [f64; 2],
    /// Channel samples at a converter rail in the data.
    pub clipped_samples: usize,
    /// Row at which the faults are injected in the fault runs (the middle of the trial).
    pub fault_row: usize,
}

/// One configuration's figures over every trial.
#[derive(Debug, Clone, Serialize)]
pub struct ConfigurationSummary {
    /// The configuration: `pyramid4` (four skewed channels, docs/design.md §4) or `stacked12` (the
    /// four units' triads stacked).
    pub configuration: &'static str,
    /// Channels per sensor type.
    pub channels: usize,
    /// The channel noise σ fitted for it and used in every trial.
    pub noise: NoiseFit,
    /// False alarm episodes over every trial, both types.
    pub false_alarms: usize,
    /// Detection and isolation of every fault run.
    #[serde(flatten)]
    pub tally: Tally,
}

/// The whole FDI evaluation: settings, totals, and the figures by configuration, fault and trial.
#[derive(Debug, Clone, Serialize)]
pub struct FdiReport {
    /// The data set directory evaluated.
    pub dir: PathBuf,
    /// Trials evaluated.
    pub trials: usize,
    /// Flights (trials) listed in the data set.
    pub flights_total: usize,
    /// Flights evaluated (equal to `trials`).
    pub flights_evaluated: usize,
    /// Recorded time of the evaluated flights, h (each configuration runs over all of it).
    pub flight_hours: f64,
    /// Trials listed but not evaluated, with the reason.
    pub skipped: Vec<SkippedTrial>,
    /// The data set's IMU rate, Hz.
    pub imu_rate_hz: f64,
    /// Gyro count resolution the data were quantised to, rad/s.
    pub gyro_lsb_rps: f64,
    /// Accelerometer count resolution, m/s².
    pub accel_lsb_mps2: f64,
    /// The detector's k-of-n persistence, `[k, n]` samples.
    pub persistence: [u32; 2],
    /// Samples of the learning phase at the start of each run (no declarations).
    pub learning_samples: u32,
    /// False alarm episodes over every trial, configuration and type.
    pub false_alarms: usize,
    /// Samples in an alarmed state without any fault, over every trial, configuration and type.
    pub false_alarm_samples: usize,
    /// Episodes of genuine over-range (not false alarms).
    pub over_range: usize,
    /// Scale-factor and misalignment disagreement allowed between channels, fraction of the
    /// measured quantity ([`super::MOTION_NOISE_FRACTION`]).
    pub motion_noise_fraction: f64,
    /// Uncertainty of the sampling instants between units, s ([`super::TIMING_SKEW_S`]).
    pub timing_skew_s: f64,
    /// Detection and isolation over every fault run.
    #[serde(flatten)]
    pub total: Tally,
    /// Figures per configuration.
    pub configurations: Vec<ConfigurationSummary>,
    /// Figures per configuration, sensor type and fault kind.
    pub breakdown: Vec<FaultBreakdown>,
    /// Figures per trial and configuration.
    pub per_trial: Vec<TrialReport>,
}

fn opt(v: Option<f64>) -> String {
    v.map_or("-".into(), |x| format!("{x:.0}"))
}

fn rate(a: usize, b: usize) -> String {
    if b == 0 {
        "-".into()
    } else {
        format!("{a}/{b} ({:.0} %)", 100.0 * a as f64 / b as f64)
    }
}

/// The report as text tables.
pub fn to_table(r: &FdiReport) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "FDI on {} ({} of {} flights, {:.3} flight hours, {} Hz; persistence {}-of-{} samples; learning {} samples; lsb gyro {:.3e} rad/s, accel {:.3e} m/s²; motion noise {} of |x|, timing skew {} ms)\n",
        r.dir.display(),
        r.flights_evaluated,
        r.flights_total,
        r.flight_hours,
        r.imu_rate_hz,
        r.persistence[0],
        r.persistence[1],
        r.learning_samples,
        r.gyro_lsb_rps,
        r.accel_lsb_mps2,
        r.motion_noise_fraction,
        r.timing_skew_s * 1e3
    );
    s.push_str(&skipped_lines(&r.skipped));
    let _ = writeln!(
        s,
        "{:22} {:9} {:>6} {:>10} {:>10} {:>11} {:>11} {:>11} {:>11} {:>7}",
        "trial",
        "config",
        "s",
        "FA gyro",
        "FA accel",
        "T/thr gyro",
        "T/thr acc",
        "σ̂ gyro °/s",
        "σ̂ acc m/s²",
        "clipped"
    );
    for t in &r.per_trial {
        let _ = writeln!(
            s,
            "{:22} {:9} {:>6.1} {:>10} {:>10} {:>11.2} {:>11.2} {:>11.3} {:>11.3} {:>7}",
            t.trial,
            t.configuration,
            t.seconds,
            t.false_alarms[0],
            t.false_alarms[1],
            t.max_t_over_threshold[0],
            t.max_t_over_threshold[1],
            t.sigma_hat[0].to_degrees(),
            t.sigma_hat[1],
            t.clipped_samples
        );
        for e in &t.alarm_episodes {
            let _ = writeln!(
                s,
                "    false alarm: {} {} at {:.1} s; loudest channel {} (IMU_{}) at {:.1}x its peers' noise",
                e.sensor, e.reason, e.at_s, e.loudest_channel, e.loudest_imu, e.noise_ratio
            );
        }
    }
    let _ = writeln!(
        s,
        "\nfalse alarms (episodes without a fault): {} ({} samples); genuine over-range episodes (Suspect, not alarms): {}\n",
        r.false_alarms, r.false_alarm_samples, r.over_range
    );
    let _ = writeln!(
        s,
        "{:9} {:5} {:10} {:>15} {:>15} {:>15} {:>17} {:>17}",
        "config",
        "type",
        "fault",
        "detected",
        "isolated",
        "correct",
        "det p50/max smp",
        "iso p50/max ms"
    );
    for b in &r.breakdown {
        let t = &b.tally;
        let _ = writeln!(
            s,
            "{:9} {:5} {:10} {:>15} {:>15} {:>15} {:>17} {:>17}",
            b.configuration,
            b.sensor,
            b.fault,
            rate(t.detected, t.faults_injected),
            rate(t.isolated, t.faults_injected),
            rate(t.correctly_isolated, t.faults_injected),
            format!(
                "{}/{}",
                opt(t.detection_delay_samples_p50),
                opt(t.detection_delay_samples_max.map(|d| d as f64))
            ),
            format!(
                "{}/{}",
                opt(t.isolation_delay_ms_p50),
                opt(t.isolation_delay_ms_max)
            ),
        );
    }
    let _ = writeln!(s);
    for c in r
        .configurations
        .iter()
        .map(|c| (c.configuration, &c.tally))
        .chain([("total", &r.total)])
    {
        let (name, t) = c;
        let _ = writeln!(
            s,
            "{name:9}: detected {}, isolated {}, correctly {}; detection delay p50 {} ms max {} ms; isolation delay p50 {} ms max {} ms",
            rate(t.detected, t.faults_injected),
            rate(t.isolated, t.faults_injected),
            rate(t.correctly_isolated, t.faults_injected),
            opt(t.detection_delay_ms_p50),
            opt(t.detection_delay_ms_max),
            opt(t.isolation_delay_ms_p50),
            opt(t.isolation_delay_ms_max),
        );
    }
    s
}
