//! `rins eval fdi DIR`: the fusion library's fault detection and isolation on the four-IMU quadrotor
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
use ipc_types::ChannelState;
use rins_eval::datasets::quadrotor::lever_arm::{estimate_lever_arms, remove_lever_arms};
use rins_eval::datasets::quadrotor::projection::{
    ChannelRow, MAX_CHANNELS, estimate_installation, project_to_pyramid, stack_triads, stacked_axes,
};
use rins_eval::datasets::quadrotor::{IMU_RATE_HZ, Trial, list_trials, load_trial};
use rins_fusion::fdi::channel_health::COUNT_MAX;
use rins_fusion::{
    ChannelNoise, FusionConfig, Geometry, GeometryConfig, ImuFuser, NoiseConfig, ParityNoise,
    PerSensor, SensorStatus, WlsSolver,
};
use serde::Serialize;

use crate::cli::EvalFdiArgs;
use crate::config;

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
    pub gyro_sigma_rps: f64,
    pub accel_sigma_mps2: f64,
}

/// The two redundant configurations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Layout {
    Pyramid4,
    Stacked12,
}

impl Layout {
    const ALL: [Layout; 2] = [Layout::Pyramid4, Layout::Stacked12];

    fn name(self) -> &'static str {
        match self {
            Layout::Pyramid4 => "pyramid4",
            Layout::Stacked12 => "stacked12",
        }
    }

    fn geometry(self) -> GeometryConfig {
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
    fn noise(self) -> NoiseFit {
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
enum Sensor {
    Gyro,
    Accel,
}

impl Sensor {
    const ALL: [Sensor; 2] = [Sensor::Gyro, Sensor::Accel];
    fn name(self) -> &'static str {
        match self {
            Sensor::Gyro => "gyro",
            Sensor::Accel => "accel",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum FaultKind {
    Dead,
    Stuck,
    /// Step of this many configured σ.
    Bias(f64),
    Saturated,
}

impl FaultKind {
    fn all() -> Vec<FaultKind> {
        let mut v = vec![FaultKind::Dead, FaultKind::Stuck];
        v.extend(BIAS_STEPS_SIGMA.map(FaultKind::Bias));
        v.push(FaultKind::Saturated);
        v
    }

    fn name(self) -> String {
        match self {
            FaultKind::Dead => "dead".into(),
            FaultKind::Stuck => "stuck".into(),
            FaultKind::Bias(s) => format!("bias {s}σ"),
            FaultKind::Saturated => "saturated".into(),
        }
    }
}

/// One trial's channels ready for the fuser.
struct Prepared {
    /// Counts per row, gyro then accel.
    gyro: Vec<[i16; MAX_CHANNELS]>,
    accel: Vec<[i16; MAX_CHANNELS]>,
    n: usize,
    /// Channel-sample pairs at a converter rail in the data itself (genuine over-range).
    clipped: usize,
    /// Per-trial parity estimate of the channel σ (for the fit), SI.
    sigma_hat: [f64; 2],
    /// Relative biases removed, SI (largest magnitude per type).
    max_bias_removed: [f64; 2],
}

fn to_counts(z: f64, lsb: f64) -> (i16, bool) {
    let c = (z / lsb).round();
    let lo = f64::from(rins_fusion::fdi::channel_health::COUNT_MIN);
    let hi = f64::from(COUNT_MAX);
    (c.clamp(lo, hi) as i16, !(lo < c && c < hi))
}

/// Estimates each channel's σ from the parity of the trial (equal σ assumed): with unit
/// variances, `T = |V_w z|²` has mean m·σ² for white channel noise.
fn parity_sigma(geometry: &Geometry, rows: &[[f64; MAX_CHANNELS]]) -> f64 {
    let n = geometry.n();
    let Ok(space) = rins_fusion::ParitySpace::new(geometry, geometry.full_mask(), &vec![1.0; n])
    else {
        return f64::NAN;
    };
    let m = space.dimension().max(1) as f64;
    let mut pw = [0.0; rins_fusion::fdi::MAX_PARITY];
    let mean_t = rows
        .iter()
        .map(|z| space.whitened_parity(z, &mut pw))
        .sum::<f64>()
        / rows.len().max(1) as f64;
    (mean_t / m).sqrt()
}

/// Relative-bias removal (see the module docs) on one sensor type's channels.
fn remove_relative_bias(geometry: &Geometry, rows: &mut [[f64; MAX_CHANNELS]]) -> Result<f64> {
    let n = geometry.n();
    let window = ((BIAS_WINDOW_S * IMU_RATE_HZ) as usize)
        .min(rows.len())
        .max(1);
    let mut mean = [0.0; MAX_CHANNELS];
    for z in &rows[..window] {
        for i in 0..n {
            mean[i] += z[i] / window as f64;
        }
    }
    let solver = WlsSolver::new(geometry, geometry.full_mask(), &vec![1.0; n])
        .map_err(|e| anyhow!("least squares over the evaluation geometry: {e}"))?;
    let (x, _) = solver.solve(&mean);
    let mut bias = [0.0; MAX_CHANNELS];
    let mut largest: f64 = 0.0;
    for (i, h) in geometry.axes().iter().enumerate() {
        bias[i] = mean[i] - (h[0] * x[0] + h[1] * x[1] + h[2] * x[2]);
        largest = largest.max(bias[i].abs());
    }
    for z in rows.iter_mut() {
        for i in 0..n {
            z[i] -= bias[i];
        }
    }
    Ok(largest)
}

fn prepare(trial: &Trial, layout: Layout, geometry: &Geometry, lsb: [f64; 2]) -> Result<Prepared> {
    let installation = estimate_installation(trial)?;
    let arms = estimate_lever_arms(trial, &installation, IMU_RATE_HZ);
    let mut trial = trial.clone();
    remove_lever_arms(&mut trial, &installation, &arms, IMU_RATE_HZ);
    let trial = &trial;
    let rows: Vec<ChannelRow> = match layout {
        Layout::Pyramid4 => project_to_pyramid(trial, &installation, geometry)?,
        Layout::Stacked12 => stack_triads(trial, &installation)?,
    };
    let n = geometry.n();
    let mut out = Prepared {
        gyro: Vec::with_capacity(rows.len()),
        accel: Vec::with_capacity(rows.len()),
        n,
        clipped: 0,
        sigma_hat: [0.0; 2],
        max_bias_removed: [0.0; 2],
    };
    for (k, sensor) in Sensor::ALL.into_iter().enumerate() {
        let mut z: Vec<[f64; MAX_CHANNELS]> = rows
            .iter()
            .map(|r| match sensor {
                Sensor::Gyro => r.gyro_rps,
                Sensor::Accel => r.accel_mps2,
            })
            .collect();
        let smooth = PREFILTER_ROWS;
        if smooth > 1 {
            let src = z.clone();
            for (j, row) in z.iter_mut().enumerate() {
                let from = j.saturating_sub(smooth - 1);
                let w = (j - from + 1) as f64;
                for i in 0..n {
                    row[i] = src[from..=j].iter().map(|r| r[i]).sum::<f64>() / w;
                }
            }
        }
        out.max_bias_removed[k] = remove_relative_bias(geometry, &mut z)?;
        out.sigma_hat[k] = parity_sigma(geometry, &z);
        let counts: Vec<[i16; MAX_CHANNELS]> = z
            .iter()
            .map(|row| {
                let mut c = [0i16; MAX_CHANNELS];
                for i in 0..n {
                    let (v, clipped) = to_counts(row[i], lsb[k]);
                    c[i] = v;
                    out.clipped += usize::from(clipped);
                }
                c
            })
            .collect();
        match sensor {
            Sensor::Gyro => out.gyro = counts,
            Sensor::Accel => out.accel = counts,
        }
    }
    Ok(out)
}

/// Anything but all-Ok on one side.
fn alarmed(s: &SensorStatus) -> bool {
    s.detected_not_isolated || s.states[..s.n].iter().any(|&st| st != ChannelState::Ok)
}

fn excluded_mask(s: &SensorStatus) -> u32 {
    s.states[..s.n]
        .iter()
        .enumerate()
        .filter(|(_, st)| **st == ChannelState::Excluded)
        .fold(0, |m, (i, _)| m | 1 << i)
}

/// The lowest channel excluded now that was not in `before`.
fn newly_excluded(s: &SensorStatus, before: u32) -> Option<usize> {
    let new = excluded_mask(s) & !before;
    (new != 0).then(|| new.trailing_zeros() as usize)
}

/// What one faulted run showed.
#[derive(Debug, Clone, Copy)]
struct Outcome {
    /// Faulty samples processed when first flagged (1 = on the first faulty sample).
    detected: Option<usize>,
    isolated: Option<(usize, usize)>,
}

fn full_valid(n: usize) -> u32 {
    let m = (1u32 << n) - 1;
    m | m << rins_fusion::fuser::ACCEL_MASK_SHIFT
}

fn run_fault(
    snapshot: &ImuFuser,
    p: &Prepared,
    t0: usize,
    sensor: Sensor,
    ch: usize,
    kind: FaultKind,
    bias_counts: f64,
) -> Outcome {
    let mut fuser = snapshot.clone();
    // Exclusions the fault-free run had already latched do not count for this fault.
    let before = match sensor {
        Sensor::Gyro => excluded_mask(fuser.monitor(ipc_types::SensorType::Gyro).status()),
        Sensor::Accel => excluded_mask(fuser.monitor(ipc_types::SensorType::Accel).status()),
    };
    let mut out = Outcome {
        detected: None,
        isolated: None,
    };
    let valid_all = full_valid(p.n);
    let shift = match sensor {
        Sensor::Gyro => 0,
        Sensor::Accel => rins_fusion::fuser::ACCEL_MASK_SHIFT,
    };
    let frozen = match sensor {
        Sensor::Gyro => p.gyro[t0.saturating_sub(1)][ch],
        Sensor::Accel => p.accel[t0.saturating_sub(1)][ch],
    };
    for k in t0..p.gyro.len() {
        let mut g = p.gyro[k];
        let mut a = p.accel[k];
        let mut valid = valid_all;
        let target = match sensor {
            Sensor::Gyro => &mut g,
            Sensor::Accel => &mut a,
        };
        match kind {
            FaultKind::Dead => valid &= !(1 << (ch as u32 + shift)),
            FaultKind::Stuck => target[ch] = frozen,
            FaultKind::Bias(_) => {
                let c = (f64::from(target[ch]) + bias_counts).round();
                target[ch] = c.clamp(-2048.0, f64::from(COUNT_MAX)) as i16;
            }
            FaultKind::Saturated => target[ch] = COUNT_MAX,
        }
        let fused = fuser.fuse(&g[..p.n], &a[..p.n], valid);
        let status = match sensor {
            Sensor::Gyro => &fused.gyro_status,
            Sensor::Accel => &fused.accel_status,
        };
        let d = k - t0 + 1;
        if out.detected.is_none() && alarmed(status) {
            out.detected = Some(d);
        }
        if let Some(x) = newly_excluded(status, before) {
            out.isolated = Some((d, x));
            break;
        }
    }
    out
}

/// Only channels held Suspect for a genuine over-range (the others put the true value beyond
/// the converter's range): a correct indication of the data, not a false alarm.
fn over_range_only(s: &SensorStatus) -> bool {
    !s.detected_not_isolated
        && s.states[..s.n]
            .iter()
            .zip(&s.reasons[..s.n])
            .all(|(st, r)| {
                *st == ChannelState::Ok
                    || (*st == ChannelState::Suspect && *r == ipc_types::FaultReason::Saturated)
            })
}

/// Fault-free run: false alarms; returns the fuser state at `t0`.
struct CleanRun {
    /// Episodes of genuine over-range per type (see [`over_range_only`]), not false alarms.
    over_range: [usize; 2],
    /// Alarm episodes (transitions into an alarmed state) per type.
    episodes: [usize; 2],
    /// Samples alarmed per type.
    samples: [usize; 2],
    /// Largest T / threshold after learning, per type.
    max_t_ratio: [f64; 2],
    /// Reasons seen at the start of each alarm episode, `type:reason` (e.g. `gyro:noisy`).
    reasons: std::collections::BTreeMap<String, usize>,
    snapshot: Option<ImuFuser>,
}

fn run_clean(fusion: &FusionConfig, lsb: [f64; 2], p: &Prepared, t0: usize) -> Result<CleanRun> {
    let mut fuser = ImuFuser::new(fusion, lsb[0], lsb[1]).map_err(|e| anyhow!("fusion: {e}"))?;
    let valid = full_valid(p.n);
    let mut run = CleanRun {
        over_range: [0; 2],
        episodes: [0; 2],
        samples: [0; 2],
        max_t_ratio: [0.0; 2],
        reasons: Default::default(),
        snapshot: None,
    };
    let mut was = [false; 2];
    let mut was_over_range = [false; 2];
    for k in 0..p.gyro.len() {
        if k == t0 {
            run.snapshot = Some(fuser.clone());
        }
        let fused = fuser.fuse(&p.gyro[k][..p.n], &p.accel[k][..p.n], valid);
        for (j, s) in [&fused.gyro_status, &fused.accel_status]
            .into_iter()
            .enumerate()
        {
            let over_range = alarmed(s) && over_range_only(s);
            run.over_range[j] += usize::from(over_range && !was_over_range[j]);
            was_over_range[j] = over_range;
            let a = alarmed(s) && !over_range;
            run.samples[j] += usize::from(a);
            run.episodes[j] += usize::from(a && !was[j]);
            if a && !was[j] {
                let why = if s.detected_not_isolated {
                    "detected-not-isolated"
                } else {
                    s.reasons[..s.n]
                        .iter()
                        .find(|r| **r != ipc_types::FaultReason::None)
                        .map_or("?", |r| r.name())
                };
                *run.reasons
                    .entry(format!("{}:{why}", Sensor::ALL[j].name()))
                    .or_default() += 1;
            }
            was[j] = a;
            if !s.learning && s.threshold.is_finite() {
                run.max_t_ratio[j] = run.max_t_ratio[j].max(s.test_statistic / s.threshold);
            }
        }
    }
    Ok(run)
}

#[derive(Debug, Clone, Default, Serialize)]
struct Tally {
    faults_injected: usize,
    detected: usize,
    isolated: usize,
    correctly_isolated: usize,
    #[serde(skip)]
    detection_delays: Vec<usize>,
    #[serde(skip)]
    isolation_delays: Vec<usize>,
    detection_delay_samples_p50: Option<f64>,
    detection_delay_samples_max: Option<usize>,
    detection_delay_ms_p50: Option<f64>,
    detection_delay_ms_max: Option<f64>,
    isolation_delay_samples_p50: Option<f64>,
    isolation_delay_samples_max: Option<usize>,
    isolation_delay_ms_p50: Option<f64>,
    isolation_delay_ms_max: Option<f64>,
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
    fn add(&mut self, o: &Outcome, channel: usize) {
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

    fn merge(&mut self, other: &Tally) {
        self.faults_injected += other.faults_injected;
        self.detected += other.detected;
        self.isolated += other.isolated;
        self.correctly_isolated += other.correctly_isolated;
        self.detection_delays.extend(&other.detection_delays);
        self.isolation_delays.extend(&other.isolation_delays);
    }

    fn finish(&mut self) {
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

#[derive(Debug, Clone, Serialize)]
struct FaultBreakdown {
    configuration: &'static str,
    sensor: &'static str,
    fault: String,
    #[serde(flatten)]
    tally: Tally,
}

#[derive(Debug, Clone, Serialize)]
struct TrialReport {
    trial: String,
    rows: usize,
    seconds: f64,
    configuration: &'static str,
    /// Alarm episodes without any fault, gyro and accel.
    false_alarms: [usize; 2],
    /// Episodes of genuine over-range (channels Suspect, saturated), gyro and accel.
    over_range: [usize; 2],
    false_alarm_samples: [usize; 2],
    /// Why the false alarms were raised, `type:reason` → episodes.
    false_alarm_reasons: std::collections::BTreeMap<String, usize>,
    /// Largest parity T / threshold after learning, gyro and accel.
    max_t_over_threshold: [f64; 2],
    /// Per-trial parity estimate of the channel σ, gyro rad/s and accel m/s².
    sigma_hat: [f64; 2],
    /// Largest relative bias removed, gyro rad/s and accel m/s².
    max_relative_bias: [f64; 2],
    /// Channel samples at a converter rail in the data.
    clipped_samples: usize,
    fault_row: usize,
}

#[derive(Debug, Clone, Serialize)]
struct ConfigurationSummary {
    configuration: &'static str,
    channels: usize,
    noise: NoiseFit,
    false_alarms: usize,
    #[serde(flatten)]
    tally: Tally,
}

#[derive(Debug, Clone, Serialize)]
struct FdiReport {
    dir: PathBuf,
    trials: usize,
    imu_rate_hz: f64,
    gyro_lsb_rps: f64,
    accel_lsb_mps2: f64,
    persistence: [u32; 2],
    learning_samples: u32,
    false_alarms: usize,
    false_alarm_samples: usize,
    /// Episodes of genuine over-range (not false alarms).
    over_range: usize,
    motion_noise_fraction: f64,
    timing_skew_s: f64,
    #[serde(flatten)]
    total: Tally,
    configurations: Vec<ConfigurationSummary>,
    breakdown: Vec<FaultBreakdown>,
    per_trial: Vec<TrialReport>,
}

/// The evaluation's fusion settings: the configured `[fusion.fdi]`, with adaptive parity noise
/// and learning/adaptive windows converted from seconds at the data's rate; the layout's
/// geometry and fitted noise; identity calibration (the data are calibrated already); the default
/// weighted least squares.
fn fusion_config(base: &rins_fusion::FdiConfig, layout: Layout) -> FusionConfig {
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

fn evaluate(args: &EvalFdiArgs) -> Result<FdiReport> {
    let cfg = config::load(args.config.as_deref())?;
    let lsb = [cfg.device.gyro_lsb_rps(), cfg.device.accel_lsb_mps2()];
    let dir = &args.dir;
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
        .filter(|e| args.trials.is_empty() || args.trials.iter().any(|t| e.name.contains(t)))
        .collect();
    if entries.is_empty() {
        return Err(anyhow!(
            "eval fdi: no trials (<group>/path_<N>/IMU_k.csv) in {}{}",
            dir.display(),
            if args.trials.is_empty() {
                String::new()
            } else {
                format!(" matching {:?}", args.trials)
            }
        ));
    }
    let faults = FaultKind::all();
    let configs: Vec<(Layout, FusionConfig, Geometry)> = Layout::ALL
        .into_iter()
        .map(|l| {
            let f = fusion_config(&cfg.fusion.fdi, l);
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
    let mut bar = super::progress::Progress::new("eval fdi");
    bar.set(0, total_runs);
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
    for entry in &entries {
        let trial =
            load_trial(&entry.path).with_context(|| format!("eval fdi: trial {}", entry.name))?;
        for (ci, (layout, fusion, geometry)) in configs.iter().enumerate() {
            let p = prepare(&trial, *layout, geometry, lsb)
                .with_context(|| format!("eval fdi: trial {}", entry.name))?;
            let t0 = p.gyro.len() / 2;
            let clean = run_clean(fusion, lsb, &p, t0)?;
            done += 1;
            bar.set(done, total_runs);
            per_trial.push(TrialReport {
                trial: trial.name.clone(),
                rows: p.gyro.len(),
                seconds: p.gyro.len() as f64 / IMU_RATE_HZ,
                configuration: layout.name(),
                false_alarms: clean.episodes,
                over_range: clean.over_range,
                false_alarm_samples: clean.samples,
                false_alarm_reasons: clean.reasons.clone(),
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
                        bar.set(done, total_runs);
                    }
                }
            }
        }
    }
    bar.finish();

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
        trials: entries.len(),
        imu_rate_hz: IMU_RATE_HZ,
        gyro_lsb_rps: lsb[0],
        accel_lsb_mps2: lsb[1],
        persistence: [cfg.fusion.fdi.persistence_k, cfg.fusion.fdi.persistence_n],
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

fn to_table(r: &FdiReport) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "FDI on {} ({} trials, {} Hz; persistence {}-of-{} samples; learning {} samples; lsb gyro {:.3e} rad/s, accel {:.3e} m/s²; motion noise {} of |x|, timing skew {} ms)\n",
        r.dir.display(),
        r.trials,
        r.imu_rate_hz,
        r.persistence[0],
        r.persistence[1],
        r.learning_samples,
        r.gyro_lsb_rps,
        r.accel_lsb_mps2,
        r.motion_noise_fraction,
        r.timing_skew_s * 1e3
    );
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
        if !t.false_alarm_reasons.is_empty() {
            let _ = writeln!(s, "    false alarms: {:?}", t.false_alarm_reasons);
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

pub fn run_fdi(args: &EvalFdiArgs) -> Result<()> {
    let report = evaluate(args)?;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print!("{}", to_table(&report));
    }
    Ok(())
}
