//! Every prepared flight run with every detector setting of the grid: the table the
//! cross-validation chooses from. The runs are independent, so they are spread over threads.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;

use anyhow::{Result, anyhow};
use rins_fusion::{FdiConfig, Geometry};

use super::candidates::{DetectorSetting, fusion_config};
use super::faults::FaultKind;
use super::layout::{Layout, Sensor};
use super::prepare::Prepared;
use super::runs::{FaultRun, run_clean, run_fault};
use super::tally::Tally;

/// One flight's channels in one layout.
pub(crate) struct PreparedFlight {
    /// Index of the flight in the evaluation's list of loaded flights.
    pub flight: usize,
    pub trial: String,
    pub layout: Layout,
    pub geometry: Geometry,
    pub p: Prepared,
    /// Other flights whose installation and arms were pooled for this one.
    pub flights_pooled: usize,
}

impl PreparedFlight {
    pub(crate) fn seconds(&self) -> f64 {
        self.p.gyro.len() as f64 / crate::datasets::quadrotor::IMU_RATE_HZ
    }

    /// The row the faults are injected at: the middle of the flight.
    pub(crate) fn fault_row(&self) -> usize {
        self.p.gyro.len() / 2
    }
}

/// What one prepared flight showed with one setting.
#[derive(Debug, Clone)]
pub(crate) struct FlightOutcome {
    /// Alarm episodes without any fault, gyro and accel.
    pub false_alarms: [usize; 2],
    pub false_alarm_samples: [usize; 2],
    pub over_range: [usize; 2],
    pub max_t_ratio: [f64; 2],
    /// Largest noise-outlier margin, gyro and accel.
    pub max_noise_peak: [f64; 2],
    /// Each false alarm's sensor, first row and reason.
    pub alarm_starts: Vec<(Sensor, usize, &'static str)>,
    /// Detection and isolation per sensor type and fault kind: index `sensor · kinds + kind`.
    pub tallies: Vec<Tally>,
}

impl FlightOutcome {
    pub(crate) fn false_alarm_episodes(&self) -> usize {
        self.false_alarms.iter().sum()
    }

    /// The closest any fault-free check came to alarming, as a fraction of its threshold: the
    /// parity statistic or the noise-outlier level, either type.
    pub(crate) fn peak_ratio(&self) -> f64 {
        self.max_t_ratio
            .iter()
            .chain(&self.max_noise_peak)
            .fold(0.0, |m, r| m.max(*r))
    }
}

/// Runs one prepared flight with one setting: the fault-free run, then every fault kind in every
/// channel of both types from the fault row.
pub(crate) fn run_setting(
    flight: &PreparedFlight,
    base: &FdiConfig,
    setting: &DetectorSetting,
    faults: &[FaultKind],
    lsb: [f64; 2],
) -> Result<FlightOutcome> {
    let fusion = fusion_config(base, flight.layout, setting);
    let t0 = flight.fault_row();
    let clean = run_clean(&fusion, lsb, &flight.p, t0)?;
    let mut out = FlightOutcome {
        false_alarms: clean.episodes,
        false_alarm_samples: clean.samples,
        over_range: clean.over_range,
        max_t_ratio: clean.max_t_ratio,
        max_noise_peak: clean.max_noise_peak,
        alarm_starts: clean.starts,
        tallies: vec![Tally::default(); 2 * faults.len()],
    };
    let Some(snapshot) = clean.snapshot else {
        return Ok(out);
    };
    let noise = flight.layout.noise();
    for (si, sensor) in Sensor::ALL.into_iter().enumerate() {
        let sigma_counts = sensor.sigma(noise) / sensor.of(lsb);
        for (fi, kind) in faults.iter().enumerate() {
            for channel in 0..flight.p.n {
                let run = FaultRun {
                    sensor,
                    channel,
                    kind: *kind,
                    sigma_counts,
                };
                let o = run_fault(&snapshot, &flight.p, t0, run);
                out.tallies[si * faults.len() + fi].add(&o, channel);
            }
        }
    }
    Ok(out)
}

/// `table[f][s]`: prepared flight `f` run with setting `s`, on `threads` threads;
/// `progress(done, total)` after each run, on the calling thread.
pub(crate) fn run_table(
    flights: &[PreparedFlight],
    base: &FdiConfig,
    settings: &[DetectorSetting],
    faults: &[FaultKind],
    lsb: [f64; 2],
    threads: usize,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<Vec<Vec<FlightOutcome>>> {
    let total = flights.len() * settings.len();
    let next = AtomicUsize::new(0);
    let (tx, rx) = mpsc::channel::<(usize, Result<FlightOutcome>)>();
    let mut cells: Vec<Option<FlightOutcome>> = vec![None; total];
    let mut first_error = None;
    std::thread::scope(|scope| {
        for _ in 0..threads.max(1) {
            let tx = tx.clone();
            let next = &next;
            scope.spawn(move || {
                loop {
                    let job = next.fetch_add(1, Ordering::Relaxed);
                    if job >= total {
                        break;
                    }
                    let (f, s) = (job / settings.len(), job % settings.len());
                    let r = run_setting(&flights[f], base, &settings[s], faults, lsb);
                    if tx.send((job, r)).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        for (done, (job, r)) in rx.iter().enumerate() {
            match r {
                Ok(o) => cells[job] = Some(o),
                Err(e) => {
                    first_error.get_or_insert(e);
                }
            }
            progress(done + 1, total);
        }
    });
    if let Some(e) = first_error {
        return Err(e);
    }
    let mut table = Vec::with_capacity(flights.len());
    let mut it = cells.into_iter();
    for f in flights {
        let row: Option<Vec<FlightOutcome>> = it.by_ref().take(settings.len()).collect();
        table.push(row.ok_or_else(|| anyhow!("eval fdi: a run of {} is missing", f.trial))?);
    }
    Ok(table)
}
