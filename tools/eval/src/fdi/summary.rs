//! From the table of runs to the report: the leave-one-flight-out choice per configuration, the
//! held-out figures per flight and fault, the ROC and the operating points.

use super::FdiRequest;
use super::candidates::{DetectorSetting, LEARNING_S};
use super::cross_validation::{choose, leave_one_out};
use super::episodes::{self, AlarmEpisode};
use super::faults::FaultKind;
use super::layout::{Layout, Sensor};
use super::report::{ConfigurationSummary, FaultBreakdown, FdiReport, OperatingPoint, TrialReport};
use super::roc::{curve, operating_probability};
use super::table::{FlightOutcome, PreparedFlight};
use super::tally::Tally;
use crate::datasets::quadrotor::{IMU_RATE_HZ, Repairs, SkippedTrial};

/// Everything the report is made from.
pub(crate) struct Inputs<'a> {
    pub request: &'a FdiRequest,
    /// Trials listed in the data set (after the filter).
    pub entries: usize,
    pub skipped: Vec<SkippedTrial>,
    pub single_unit: Vec<SkippedTrial>,
    pub repairs: Repairs,
    pub prepared: &'a [PreparedFlight],
    pub table: &'a [Vec<FlightOutcome>],
    pub settings: &'a [DetectorSetting],
    pub faults: &'a [FaultKind],
}

/// The setting a flight falls back to when its configuration has no other flight: the middle
/// of the grid (the centre of every range).
fn middle_setting(settings: &[DetectorSetting]) -> usize {
    settings.len() / 2
}

fn trial_report(p: &PreparedFlight, o: &FlightOutcome, setting: DetectorSetting) -> TrialReport {
    let half_window = (episodes::EVIDENCE_HALF_WINDOW_S * IMU_RATE_HZ) as usize;
    let alarm_episodes = o
        .alarm_starts
        .iter()
        .map(|&(sensor, row, reason)| {
            let (ch, ratio) =
                episodes::loudest_channel(&p.p, &p.geometry, sensor, row, half_window);
            AlarmEpisode {
                sensor: sensor.name(),
                at_s: row as f64 / IMU_RATE_HZ,
                reason,
                loudest_channel: ch,
                loudest_imu: p.layout.unit_of(ch) + 1,
                noise_ratio: ratio,
            }
        })
        .collect();
    TrialReport {
        trial: p.trial.clone(),
        rows: p.p.gyro.len(),
        seconds: p.seconds(),
        configuration: p.layout.name(),
        false_alarms: o.false_alarms,
        over_range: o.over_range,
        false_alarm_samples: o.false_alarm_samples,
        alarm_episodes,
        max_t_over_threshold: o.max_t_ratio,
        sigma_hat: p.p.sigma_hat,
        max_relative_bias: p.p.max_bias_removed,
        clipped_samples: p.p.clipped,
        fault_row: p.fault_row(),
        setting,
        geometry_flights_pooled: p.flights_pooled,
    }
}

pub(crate) fn summarise(i: Inputs<'_>) -> FdiReport {
    let Inputs {
        request,
        entries,
        skipped,
        single_unit,
        repairs,
        prepared,
        table,
        settings,
        faults,
    } = i;
    let mut layouts: Vec<Layout> = Vec::new();
    for p in prepared {
        if !layouts.contains(&p.layout) {
            layouts.push(p.layout);
        }
    }
    let all: Vec<usize> = (0..settings.len()).collect();
    let mut per_trial = Vec::new();
    let mut breakdown = Vec::new();
    let mut configurations = Vec::new();
    let mut roc = Vec::new();
    let mut operating_points = Vec::new();
    let mut total = Tally::default();
    for layout in layouts {
        let flights: Vec<usize> = (0..prepared.len())
            .filter(|&f| prepared[f].layout == layout)
            .collect();
        let chosen = leave_one_out(table, &flights, &all, faults, middle_setting(settings));
        let mut tallies = vec![Tally::default(); 2 * faults.len()];
        let mut false_alarms = 0;
        for (&f, &s) in flights.iter().zip(&chosen) {
            let o = &table[f][s];
            false_alarms += o.false_alarm_episodes();
            for (t, add) in tallies.iter_mut().zip(&o.tallies) {
                t.merge(add);
            }
            per_trial.push(trial_report(&prepared[f], o, settings[s]));
        }
        let mut config_tally = Tally::default();
        for (si, sensor) in Sensor::ALL.into_iter().enumerate() {
            for (fi, kind) in faults.iter().enumerate() {
                let mut tally = tallies[si * faults.len() + fi].clone();
                config_tally.merge(&tally);
                tally.finish();
                breakdown.push(FaultBreakdown {
                    configuration: layout.name(),
                    sensor: sensor.name(),
                    fault: kind.name(),
                    tally,
                });
            }
        }
        total.merge(&config_tally);
        config_tally.finish();
        let hours: f64 = flights.iter().map(|&f| prepared[f].seconds()).sum::<f64>() / 3600.0;
        let per_hour = |n: usize| if hours > 0.0 { n as f64 / hours } else { 0.0 };
        let channels = prepared[flights[0]].p.n;
        configurations.push(ConfigurationSummary {
            configuration: layout.name(),
            channels,
            flights: flights.len(),
            flight_hours: hours,
            noise: layout.noise(),
            false_alarms,
            cv_false_alarms: false_alarms,
            cv_false_alarms_per_hour: per_hour(false_alarms),
            tally: config_tally,
        });
        let points = curve(layout.name(), table, prepared, &flights, settings, faults);
        if let Some(p) = operating_probability(&points, faults) {
            let at_p: Vec<usize> = (0..settings.len())
                .filter(|&s| settings[s].false_alarm_probability == p)
                .collect();
            let point = points.iter().find(|q| q.false_alarm_probability == p);
            if let (Some(s), Some(point)) = (choose(table, &flights, &at_p, faults), point) {
                operating_points.push(OperatingPoint {
                    configuration: layout.name(),
                    setting: settings[s],
                    cv_false_alarms_per_hour: point.false_alarms_per_hour,
                });
            }
        }
        roc.extend(points);
    }
    total.finish();
    let mut evaluated: Vec<usize> = prepared.iter().map(|p| p.flight).collect();
    evaluated.dedup();
    let flight_s: f64 = {
        let mut seen = Vec::new();
        prepared
            .iter()
            .filter(|p| {
                let new = !seen.contains(&p.flight);
                seen.push(p.flight);
                new
            })
            .map(PreparedFlight::seconds)
            .sum()
    };
    let false_alarms = per_trial
        .iter()
        .map(|r| r.false_alarms.iter().sum::<usize>())
        .sum();
    let first = operating_points.first().map(|o| o.setting);
    FdiReport {
        dir: request.dir.clone(),
        trials: evaluated.len(),
        flights_total: entries,
        flights_evaluated: evaluated.len(),
        flight_hours: flight_s / 3600.0,
        skipped,
        single_unit,
        repairs,
        settings_grid: settings.len(),
        imu_rate_hz: IMU_RATE_HZ,
        gyro_lsb_rps: request.lsb[0],
        accel_lsb_mps2: request.lsb[1],
        persistence: [request.fdi.persistence_k, request.fdi.persistence_n],
        learning_samples: (LEARNING_S * IMU_RATE_HZ) as u32,
        false_alarms,
        cv_false_alarms: false_alarms,
        false_alarm_samples: per_trial
            .iter()
            .map(|r| r.false_alarm_samples.iter().sum::<usize>())
            .sum(),
        over_range: per_trial
            .iter()
            .map(|r| r.over_range.iter().sum::<usize>())
            .sum(),
        motion_noise_fraction: first.map_or(f64::NAN, |s| s.motion_noise_fraction),
        timing_skew_s: first.map_or(f64::NAN, |s| s.timing_skew_s),
        total,
        configurations,
        breakdown,
        per_trial,
        roc,
        operating_points,
    }
}
