//! The evaluation's report: per-trial rows, breakdowns and summaries of the tallies, and the
//! text tables.

use std::path::PathBuf;

use serde::Serialize;

use super::candidates::DetectorSetting;
use super::layout::NoiseFit;
use super::roc::RocPoint;
use super::tally::Tally;
use crate::datasets::quadrotor::{Repairs, SkippedTrial, skipped_lines};

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
    /// The detector setting this flight was scored with, chosen on the other flights.
    pub setting: DetectorSetting,
    /// Other flights whose installation rotations and lever arms were used for this one (0: its
    /// own, no other flight had the same units).
    pub geometry_flights_pooled: usize,
}

/// The setting a configuration would be deployed with: chosen on every flight, its false-alarm
/// probability read off the cross-validated ROC.
#[derive(Debug, Clone, Serialize)]
pub struct OperatingPoint {
    /// The configuration.
    pub configuration: &'static str,
    /// The chosen setting.
    pub setting: DetectorSetting,
    /// The cross-validated false alarms per flight hour at its false-alarm probability.
    pub cv_false_alarms_per_hour: f64,
}

/// One configuration's figures over every trial.
#[derive(Debug, Clone, Serialize)]
pub struct ConfigurationSummary {
    /// The configuration: `pyramid4` (four skewed channels, docs/design.md §4) or `stacked12` (the
    /// four units' triads stacked).
    pub configuration: &'static str,
    /// Channels per sensor type.
    pub channels: usize,
    /// Flights evaluated in it.
    pub flights: usize,
    /// Their recorded time, h.
    pub flight_hours: f64,
    /// The reference σ (unit of the injected fault sizes, centre of the detector σ grid).
    pub noise: NoiseFit,
    /// False alarm episodes over every flight, both types, each flight with the setting chosen
    /// on the others.
    pub false_alarms: usize,
    /// The same (the cross-validated figure, named as such).
    pub cv_false_alarms: usize,
    /// Those per flight hour.
    pub cv_false_alarms_per_hour: f64,
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
    /// Trials (or trial configurations) listed but not evaluated, with the reason.
    pub skipped: Vec<SkippedTrial>,
    /// Flights with a single usable unit: no redundancy to monitor, listed, not evaluated.
    pub single_unit: Vec<SkippedTrial>,
    /// What the loader repaired in the recordings (and trials it could not load).
    pub repairs: Repairs,
    /// Detector settings in the grid the cross-validation chooses from.
    pub settings_grid: usize,
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
    /// False alarm episodes over every trial, configuration and type, each flight scored with the
    /// setting chosen on the other flights.
    pub false_alarms: usize,
    /// The same (the cross-validated figure, named as such).
    pub cv_false_alarms: usize,
    /// Samples in an alarmed state without any fault, over every trial, configuration and type.
    pub false_alarm_samples: usize,
    /// Episodes of genuine over-range (not false alarms).
    pub over_range: usize,
    /// Scale-factor and misalignment disagreement allowed between channels, fraction of the
    /// measured quantity: the first configuration's operating point.
    pub motion_noise_fraction: f64,
    /// Uncertainty of the sampling instants between units, s: the first configuration's
    /// operating point.
    pub timing_skew_s: f64,
    /// The cross-validated ROC of every configuration.
    pub roc: Vec<RocPoint>,
    /// The setting each configuration would be deployed with.
    pub operating_points: Vec<OperatingPoint>,
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
        "FDI on {} ({} of {} flights, {:.3} flight hours, {} Hz; persistence {}-of-{} samples; learning {} samples; lsb gyro {:.3e} rad/s, accel {:.3e} m/s²)\nEvery figure is leave-one-flight-out: each flight is scored with the detector setting chosen on the other flights from {} settings (false-alarm probability, detector σ, motion noise, timing skew), with the installation and lever arms of the other flights.\n",
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
        r.settings_grid,
    );
    s.push_str(&skipped_lines(&r.skipped));
    s.push_str(&skipped_lines(&r.single_unit));
    let _ = writeln!(
        s,
        "repaired in the recordings: {} counter wraps, {} repeated timestamps, {} missing samples filled, {} non-finite rows, {} rows dropped, {} unit files skipped, {} trials not loadable\n",
        r.repairs.counter_wraps,
        r.repairs.repeated_timestamps,
        r.repairs.missing_samples_filled,
        r.repairs.non_finite_rows,
        r.repairs.rows_dropped,
        r.repairs.imu_files_skipped,
        r.repairs.trials_failed
    );
    let _ = writeln!(
        s,
        "{:22} {:9} {:>6} {:>10} {:>10} {:>11} {:>11} {:>11} {:>11} {:>7} {:>34}",
        "trial",
        "config",
        "s",
        "FA gyro",
        "FA accel",
        "T/thr gyro",
        "T/thr acc",
        "σ̂ gyro °/s",
        "σ̂ acc m/s²",
        "clipped",
        "setting: Pfa σ× motion skew noise"
    );
    for t in &r.per_trial {
        let _ = writeln!(
            s,
            "{:22} {:9} {:>6.1} {:>10} {:>10} {:>11.2} {:>11.2} {:>11.3} {:>11.3} {:>7} {:>34}",
            t.trial,
            t.configuration,
            t.seconds,
            t.false_alarms[0],
            t.false_alarms[1],
            t.max_t_over_threshold[0],
            t.max_t_over_threshold[1],
            t.sigma_hat[0].to_degrees(),
            t.sigma_hat[1],
            t.clipped_samples,
            setting_text(&t.setting)
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
        "\ncross-validated false alarms (episodes without a fault): {} ({} samples, {:.2} per flight hour); genuine over-range episodes (Suspect, not alarms): {}",
        r.cv_false_alarms,
        r.false_alarm_samples,
        r.cv_false_alarms as f64 / r.flight_hours.max(f64::MIN_POSITIVE),
        r.over_range
    );
    for c in &r.configurations {
        let _ = writeln!(
            s,
            "  {:9}: {} episodes in {} flights ({:.3} h): {:.2} per flight hour",
            c.configuration,
            c.cv_false_alarms,
            c.flights,
            c.flight_hours,
            c.cv_false_alarms_per_hour
        );
    }
    let _ = writeln!(s);
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
    s.push_str(&roc_table(r));
    s
}

fn setting_text(t: &DetectorSetting) -> String {
    format!(
        "{:.0e} {:.1} {:.2} {:.0}ms {:.0}",
        t.false_alarm_probability,
        t.noise_scale,
        t.motion_noise_fraction,
        t.timing_skew_s * 1e3,
        t.noise_ratio
    )
}

/// The cross-validated ROC and the operating points as text.
fn roc_table(r: &FdiReport) -> String {
    use std::fmt::Write as _;
    let mut s = String::from(
        "\ncross-validated ROC (each flight with the other settings chosen on the other flights):\n",
    );
    let kinds: Vec<&str> = r
        .roc
        .first()
        .map(|p| p.detection.iter().map(|d| d.fault.as_str()).collect())
        .unwrap_or_default();
    let _ = write!(s, "{:9} {:>7} {:>5} {:>7}", "config", "Pfa", "FA", "FA/h");
    for k in &kinds {
        let _ = write!(s, " {k:>11}");
    }
    let _ = writeln!(s);
    for p in &r.roc {
        let _ = write!(
            s,
            "{:9} {:>7.0e} {:>5} {:>7.2}",
            p.configuration, p.false_alarm_probability, p.false_alarms, p.false_alarms_per_hour
        );
        for d in &p.detection {
            let _ = write!(s, " {:>10.1}%", 100.0 * d.rate);
        }
        let _ = writeln!(s);
    }
    for o in &r.operating_points {
        let _ = writeln!(
            s,
            "operating point {:9}: {} (Pfa, σ×, motion, skew, noise ratio; {:.2} false alarms per flight hour cross-validated)",
            o.configuration,
            setting_text(&o.setting),
            o.cv_false_alarms_per_hour
        );
    }
    s
}
