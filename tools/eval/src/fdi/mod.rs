//! Fault detection and isolation on the four-IMU quadrotor
//! recordings (real rotor vibration), in-process.
//!
//! Two redundant configurations are built from every trial:
//! - `pyramid4`: channel i = IMU i projected on the pyramid axis h_i (α = 28.7°, β0 = 45°), one
//!   single-axis channel per IMU as on the product's block;
//! - `stacked12`: the four triads turned into the reference IMU's frame, 12 rows.
//!
//! Pre-processing, the same fixed rules for every trial (no per-trial tuning):
//! 1. IMU lags from the loader (|ω| cross-matching), installation rotations from the data (Wahba
//!    on the centred gyro vectors).
//! 2. A 4-row moving average against rotor vibration ([`PREFILTER_ROWS`]).
//! 3. Relative bias removal: over the first [`BIAS_WINDOW_S`] the mean of each channel is split
//!    into the part a common motion explains (`H x̂`, least squares) and the rest, the
//!    inconsistency between IMUs (relative biases); the rest is subtracted from every sample.
//!    The common motion is left alone, so the fused rate keeps its content.
//! 4. Channels → 12-bit counts at the product's converter resolution (`[device]` full scales),
//!    so that the fuser's real path runs: calibration, channel health (stuck, saturation) on the
//!    counts, parity with persistence, isolation, exclusion.
//! 5. Channel noise: one σ per sensor type and configuration, [`NoiseFit`], for every trial,
//!    with `parity_noise = "adaptive"` seeded from it.
//!
//! Faults are injected at the middle row of each trial into one channel of one type: dead (valid
//! bit cleared), stuck (the count frozen), bias steps of 5σ and 20σ, saturation (count at the
//! upper rail). The fault-free run is deterministic, so each faulted run starts from a copy of
//! the fault-free fuser at the fault row.

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use rins_fusion::{
    ChannelNoise, FdiConfig, FusionConfig, Geometry, GeometryConfig, NoiseConfig, ParityNoise,
    PerSensor,
};
use serde::Serialize;

use crate::datasets::quadrotor::projection::stacked_axes;
use crate::datasets::quadrotor::{IMU_RATE_HZ, MAX_IMUS, SkippedTrial, list_trials, load_trial};

mod episodes;
mod prepare;
mod report;
mod runs;

pub use episodes::AlarmEpisode;
use prepare::prepare;
pub use report::{ConfigurationSummary, FaultBreakdown, FdiReport, Tally, TrialReport, to_table};
use runs::{run_clean, run_fault};

/// What to evaluate: the data set, an optional trial filter, the fault detection settings and
/// the converter resolution of the product.
#[derive(Debug, Clone)]
pub struct FdiRequest {
    /// Data set directory (`<group>/path_<N>/IMU_k.csv`).
    pub dir: PathBuf,
    /// Only trials whose name contains one of these (all when empty).
    pub trials: Vec<String>,
    /// The configured `[fusion.fdi]` (see [`fusion_config`] for what the evaluation changes).
    pub fdi: FdiConfig,
    /// Gyro and accelerometer count resolution, rad/s and m/s².
    pub lsb: [f64; 2],
}

/// Length of the window at the start of each trial over which relative biases are measured, s.
pub const BIAS_WINDOW_S: f64 = 2.0;
/// Moving average over this many rows (33 ms) before everything else: rotor vibration, which the
/// units see differently (frame flexing, lever arms, residual sub-row lag), dominates the
/// disagreement between IMUs at 120 Hz; averaging over 4 rows cuts the parity noise by about 3
/// (gyro) and 4 (accel). Faults are injected after it, i.e. into the band-limited outputs.
pub const PREFILTER_ROWS: usize = 4;
/// Learning phase of the parity offset and adaptive noise, s (declarations suspended).
pub const LEARNING_S: f64 = 2.0;
/// Averaging length of the adaptive parity noise, s.
pub const ADAPTIVE_WINDOW_S: f64 = 10.0;
/// Scale-factor and misalignment disagreement allowed between the units' channels, as a
/// fraction of the measured quantity (consumer MEMS units: scale and cross-axis tolerances of
/// 1–2 % each, plus the error of the estimated installation).
pub const MOTION_NOISE_FRACTION: f64 = 0.03;
/// Uncertainty of the sampling instants between the units, s: each unit samples somewhere in its
/// own 8.3 ms period (±4.2 ms) and the sub-row lag estimate wanders by ±0.2 rows (±1.7 ms).
/// A single sensor block on one converter clock has no such term.
pub const TIMING_SKEW_S: f64 = 0.006;
/// Bias step sizes injected, in units of the configured channel σ.
pub const BIAS_STEPS_SIGMA: [f64; 2] = [5.0, 20.0];

/// Fixed channel noise σ (SI) of one configuration, fitted once to the whole data set (pooled
/// median of the per-trial parity estimates printed in the report) and used for every trial.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct NoiseFit {
    /// Gyro channel noise σ, rad/s.
    pub gyro_sigma_rps: f64,
    /// Accelerometer channel noise σ, m/s².
    pub accel_sigma_mps2: f64,
}

/// The two redundant configurations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Layout {
    Pyramid4,
    Stacked12,
}

impl Layout {
    pub(crate) const ALL: [Layout; 2] = [Layout::Pyramid4, Layout::Stacked12];

    pub(crate) fn name(self) -> &'static str {
        match self {
            Layout::Pyramid4 => "pyramid4",
            Layout::Stacked12 => "stacked12",
        }
    }

    pub(crate) fn geometry(self) -> GeometryConfig {
        match self {
            Layout::Pyramid4 => GeometryConfig::Pyramid {
                n: 4,
                alpha_deg: 28.7,
                beta0_deg: 45.0,
            },
            Layout::Stacked12 => GeometryConfig::Axes {
                axes: stacked_axes(4),
            },
        }
    }

    /// σ per type, from the pooled median of the per-trial parity estimates on the whole set
    /// (see the pre-processing table of the report).
    pub(crate) fn noise(self) -> NoiseFit {
        match self {
            Layout::Pyramid4 => NoiseFit {
                gyro_sigma_rps: 0.023,
                accel_sigma_mps2: 0.7,
            },
            Layout::Stacked12 => NoiseFit {
                gyro_sigma_rps: 0.019,
                accel_sigma_mps2: 0.7,
            },
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Sensor {
    Gyro,
    Accel,
}

impl Sensor {
    pub(crate) const ALL: [Sensor; 2] = [Sensor::Gyro, Sensor::Accel];
    pub(crate) fn name(self) -> &'static str {
        match self {
            Sensor::Gyro => "gyro",
            Sensor::Accel => "accel",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FaultKind {
    Dead,
    Stuck,
    /// Step of this many configured σ.
    Bias(f64),
    Saturated,
}

impl FaultKind {
    pub(crate) fn all() -> Vec<FaultKind> {
        let mut v = vec![FaultKind::Dead, FaultKind::Stuck];
        v.extend(BIAS_STEPS_SIGMA.map(FaultKind::Bias));
        v.push(FaultKind::Saturated);
        v
    }

    pub(crate) fn name(self) -> String {
        match self {
            FaultKind::Dead => "dead".into(),
            FaultKind::Stuck => "stuck".into(),
            FaultKind::Bias(s) => format!("bias {s}σ"),
            FaultKind::Saturated => "saturated".into(),
        }
    }
}

/// The evaluation's fusion settings: the configured `[fusion.fdi]`, with adaptive parity noise
/// and learning/adaptive windows converted from seconds at the data's rate; the layout's
/// geometry and fitted noise; identity calibration (the data are calibrated already); the default
/// weighted least squares.
pub(crate) fn fusion_config(base: &FdiConfig, layout: Layout) -> FusionConfig {
    let noise = layout.noise();
    let mut fdi = base.clone();
    fdi.parity_noise = ParityNoise::Adaptive;
    fdi.learning_samples = (LEARNING_S * IMU_RATE_HZ) as u32;
    fdi.adaptive_window = (ADAPTIVE_WINDOW_S * IMU_RATE_HZ) as u32;
    fdi.motion_noise_fraction = MOTION_NOISE_FRACTION;
    fdi.timing_skew_s = TIMING_SKEW_S;
    FusionConfig {
        geometry: PerSensor {
            gyro: layout.geometry(),
            accel: layout.geometry(),
        },
        noise: NoiseConfig {
            gyro_sigma_rps: ChannelNoise::Uniform(noise.gyro_sigma_rps),
            accel_sigma_mps2: ChannelNoise::Uniform(noise.accel_sigma_mps2),
        },
        calibration: PerSensor::default(),
        fdi,
        // The flights start in motion: no estimate of channel biases at rest (the relative
        // biases are removed in the pre-processing instead).
        rest_bias_s: 0.0,
        sample_rate_hz: IMU_RATE_HZ,
        ..FusionConfig::default()
    }
}

/// Runs the evaluation; `progress(done, total)` after each fuser run.
pub fn evaluate(request: &FdiRequest, progress: &mut dyn FnMut(usize, usize)) -> Result<FdiReport> {
    let lsb = request.lsb;
    let dir = &request.dir;
    if !dir.is_dir() {
        return Err(anyhow!(
            "eval fdi: data set directory {} does not exist or is not a directory",
            dir.display()
        ));
    }
    let entries = list_trials(dir)
        .with_context(|| format!("eval fdi: cannot list trials in {}", dir.display()))?;
    let entries: Vec<_> = entries
        .into_iter()
        .filter(|e| request.trials.is_empty() || request.trials.iter().any(|t| e.name.contains(t)))
        .collect();
    if entries.is_empty() {
        return Err(anyhow!(
            "eval fdi: no trials (<group>/path_<N>/IMU_k.csv) in {}{}",
            dir.display(),
            if request.trials.is_empty() {
                String::new()
            } else {
                format!(" matching {:?}", request.trials)
            }
        ));
    }
    let faults = FaultKind::all();
    let configs: Vec<(Layout, FusionConfig, Geometry)> = Layout::ALL
        .into_iter()
        .map(|l| {
            let f = fusion_config(&request.fdi, l);
            f.validate().map_err(|e| anyhow!("fusion: {e}"))?;
            let g = l.geometry().build().map_err(|e| anyhow!("geometry: {e}"))?;
            Ok((l, f, g))
        })
        .collect::<Result<_>>()?;
    let runs_per_trial: usize = configs
        .iter()
        .map(|(_, _, g)| 1 + 2 * g.n() * faults.len())
        .sum();
    let total_runs = runs_per_trial * entries.len();
    progress(0, total_runs);
    let mut done = 0;

    let mut per_trial = Vec::new();
    let mut breakdown: Vec<FaultBreakdown> = Vec::new();
    for (layout, _, _) in &configs {
        for sensor in Sensor::ALL {
            for f in &faults {
                breakdown.push(FaultBreakdown {
                    configuration: layout.name(),
                    sensor: sensor.name(),
                    fault: f.name(),
                    tally: Tally::default(),
                });
            }
        }
    }
    let mut skipped = Vec::new();
    let mut flight_s = 0.0;
    for entry in &entries {
        // A trial that cannot be loaded, or has fewer units than the configurations are built
        // from, is listed in the report; its runs still count, so the bar ends at its total.
        let reason = match load_trial(&entry.path) {
            Ok(trial) if trial.imus.len() == MAX_IMUS => Ok(trial),
            Ok(trial) => Err(format!(
                "{} IMUs usable, the configurations need {MAX_IMUS}",
                trial.imus.len()
            )),
            Err(e) => Err(e.to_string()),
        };
        let trial = match reason {
            Ok(trial) => trial,
            Err(reason) => {
                skipped.push(SkippedTrial {
                    trial: entry.name.clone(),
                    reason,
                });
                done += runs_per_trial;
                progress(done, total_runs);
                continue;
            }
        };
        flight_s += trial.len() as f64 / IMU_RATE_HZ;
        for (ci, (layout, fusion, geometry)) in configs.iter().enumerate() {
            let p = prepare(&trial, *layout, geometry, lsb)
                .with_context(|| format!("eval fdi: trial {}", entry.name))?;
            let t0 = p.gyro.len() / 2;
            let clean = run_clean(fusion, lsb, &p, t0)?;
            let half_window = (episodes::EVIDENCE_HALF_WINDOW_S * IMU_RATE_HZ) as usize;
            let alarm_episodes = clean
                .starts
                .iter()
                .map(|&(sensor, row, reason)| {
                    let (ch, ratio) =
                        episodes::loudest_channel(&p, geometry, sensor, row, half_window);
                    AlarmEpisode {
                        sensor: sensor.name(),
                        at_s: row as f64 / IMU_RATE_HZ,
                        reason,
                        loudest_channel: ch,
                        loudest_imu: layout.unit_of(ch) + 1,
                        noise_ratio: ratio,
                    }
                })
                .collect();
            done += 1;
            progress(done, total_runs);
            per_trial.push(TrialReport {
                trial: trial.name.clone(),
                rows: p.gyro.len(),
                seconds: p.gyro.len() as f64 / IMU_RATE_HZ,
                configuration: layout.name(),
                false_alarms: clean.episodes,
                over_range: clean.over_range,
                false_alarm_samples: clean.samples,
                alarm_episodes,
                max_t_over_threshold: clean.max_t_ratio,
                sigma_hat: p.sigma_hat,
                max_relative_bias: p.max_bias_removed,
                clipped_samples: p.clipped,
                fault_row: t0,
            });
            let Some(snapshot) = clean.snapshot else {
                continue;
            };
            let noise = layout.noise();
            for (si, sensor) in Sensor::ALL.into_iter().enumerate() {
                let sigma = match sensor {
                    Sensor::Gyro => noise.gyro_sigma_rps,
                    Sensor::Accel => noise.accel_sigma_mps2,
                };
                for (fi, kind) in faults.iter().enumerate() {
                    let bias_counts = match kind {
                        FaultKind::Bias(k) => k * sigma / lsb[si],
                        _ => 0.0,
                    };
                    let slot = (ci * 2 + si) * faults.len() + fi;
                    for ch in 0..p.n {
                        let o = run_fault(&snapshot, &p, t0, sensor, ch, *kind, bias_counts);
                        breakdown[slot].tally.add(&o, ch);
                        done += 1;
                        progress(done, total_runs);
                    }
                }
            }
        }
    }

    let mut total = Tally::default();
    let mut configurations = Vec::new();
    for (layout, _, geometry) in &configs {
        let mut t = Tally::default();
        for b in breakdown
            .iter()
            .filter(|b| b.configuration == layout.name())
        {
            t.merge(&b.tally);
        }
        total.merge(&t);
        t.finish();
        configurations.push(ConfigurationSummary {
            configuration: layout.name(),
            channels: geometry.n(),
            noise: layout.noise(),
            false_alarms: per_trial
                .iter()
                .filter(|r| r.configuration == layout.name())
                .map(|r| r.false_alarms.iter().sum::<usize>())
                .sum(),
            tally: t,
        });
    }
    total.finish();
    breakdown.iter_mut().for_each(|b| b.tally.finish());
    Ok(FdiReport {
        dir: dir.clone(),
        trials: entries.len() - skipped.len(),
        flights_total: entries.len(),
        flights_evaluated: entries.len() - skipped.len(),
        flight_hours: flight_s / 3600.0,
        skipped,
        imu_rate_hz: IMU_RATE_HZ,
        gyro_lsb_rps: lsb[0],
        accel_lsb_mps2: lsb[1],
        persistence: [request.fdi.persistence_k, request.fdi.persistence_n],
        learning_samples: (LEARNING_S * IMU_RATE_HZ) as u32,
        false_alarms: per_trial
            .iter()
            .map(|r| r.false_alarms.iter().sum::<usize>())
            .sum(),
        false_alarm_samples: per_trial
            .iter()
            .map(|r| r.false_alarm_samples.iter().sum::<usize>())
            .sum(),
        over_range: per_trial
            .iter()
            .map(|r| r.over_range.iter().sum::<usize>())
            .sum(),
        motion_noise_fraction: MOTION_NOISE_FRACTION,
        timing_skew_s: TIMING_SKEW_S,
        total,
        configurations,
        breakdown,
        per_trial,
    })
}
