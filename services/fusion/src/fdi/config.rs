//! The `[fusion.fdi]` table: fault detection, isolation and reconfiguration settings.

use super::MAX_PARITY;
use super::channel_health::HealthSettings;
use super::chi2::{chi2_upper_quantile, regularized_gamma_p};
use super::persistence::{MAX_PERSISTENCE_WINDOW, exceedance_probability};
use super::stationary::StationarySettings;
use crate::error::ConfigError;
use serde::{Deserialize, Serialize};

/// Which parity noise covariance the detector whitens with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ParityNoise {
    /// `V R Vᵀ` from the configured channel noise.
    #[default]
    Configured,
    /// A slow estimate from fault-free samples, seeded from the configured one (see
    /// [`super::noise_estimate`]).
    Adaptive,
}

/// What happens to latched exclusions when a sensor type has lost its solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ReadmitPolicy {
    /// With fewer than three channels in service, the excluded channels are re-tested and those
    /// consistent again for `readmit_after_samples` return by themselves (see
    /// [`super::recovery`]).
    #[default]
    Auto,
    /// Exclusions latch until an operator re-admits the channel, whatever the consequences.
    Operator,
}

/// Fault detection and isolation settings. Sample counts are at the IMU rate.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct FdiConfig {
    /// Probability that a fault-free sample raises a (persistent, k-of-n) parity alarm. The
    /// per-sample χ² threshold follows from it (see [`super::persistence`]): 1e-7 gives 0.36
    /// false alarms per hour per sensor type at 1 kHz, the default 1e-10 gives 3.6e-4.
    pub false_alarm_probability: f64,
    /// Exceedances needed within the last `persistence_n` samples to declare a fault.
    pub persistence_k: u32,
    /// Length of the persistence window, 1..=16 samples.
    pub persistence_n: u32,
    /// GLT isolation margin: the winner's score must exceed every other signature's by this
    /// much (twice the log-likelihood ratio; see [`super::isolation`]).
    pub isolation_margin: f64,
    /// `"configured"` or `"adaptive"` parity noise covariance.
    pub parity_noise: ParityNoise,
    /// Averaging length of the adaptive noise estimate, samples.
    pub adaptive_window: u32,
    /// Averaging length of the parity offset estimate, samples (0: no offset estimate; see
    /// [`super::offset`]).
    pub parity_offset_window: u32,
    /// Learn, with the parity offset, how the parity grows with the fused value — the channels'
    /// relative scale factor and misalignment errors as the parity sees them — and take it out
    /// before the test (see [`super::offset`]). Needs `parity_offset_window`.
    pub motion_offset: bool,
    /// Averaging length of the mean-shift test, samples (0: off; see [`super::mean_shift`]):
    /// finds biases too small for the per-sample test, at the same false-alarm probability per
    /// window.
    pub mean_shift_window: u32,
    /// Learning phase at start, samples: the parity offset (and the adaptive noise) are learnt,
    /// parity declarations are suspended. Ignored when neither estimate is in use.
    pub learning_samples: u32,
    /// Samples in a row at a converter rail before a channel counts as saturated.
    pub saturation_samples: u32,
    /// Identical counts in a row that make a channel stuck (see [`super::channel_health`]).
    pub stuck_samples: u32,
    /// Block length of the noise-outlier check, samples.
    pub noise_window: u32,
    /// A channel is noisy when its first-difference variance exceeds this multiple of the median
    /// of the other channels'.
    pub noise_ratio: f64,
    /// Block length of the stationary detector, s (turned into samples at the IMU rate: the
    /// blocks that make the zero-rate/gravity reference span the same time at every rate).
    pub stationary_window_s: f64,
    /// Largest per-axis standard deviation of the fused rate while stationary, rad/s.
    pub stationary_rate_spread_rps: f64,
    /// Largest per-axis standard deviation of the fused specific force while stationary, m/s².
    pub stationary_force_spread_mps2: f64,
    /// Largest mean fused rate while stationary, rad/s.
    pub stationary_max_rate_rps: f64,
    /// How much the departure of the isolated channel from the stationary reference must exceed
    /// every other channel's (ratio of standard scores).
    pub reference_ratio: f64,
    /// Channel error proportional to the measured quantity (scale factor and misalignment
    /// uncertainty between channels), as a fraction of |fused value|: adds (f·|x|)² to every
    /// channel's variance in the parity test, so fast manoeuvres do not read as faults.
    pub motion_noise_fraction: f64,
    /// Uncertainty of the sampling instants between channels, s: adds (τ·|dx/dt|)² to every
    /// channel's variance in the parity test (units on separate clocks; 0 for one converter).
    pub timing_skew_s: f64,
    /// `"auto"` or `"operator"`: whether a sensor type left without a solution re-admits its
    /// excluded channels once they are consistent again (see [`ReadmitPolicy`]).
    pub readmit: ReadmitPolicy,
    /// Samples in a row an excluded channel must be valid, off the converter rails, varying and
    /// consistent with the others before it returns by itself.
    pub readmit_after_samples: u32,
    /// Samples a channel re-admitted by command is tested against the other channels, out of the
    /// solution, before it rejoins and the command is answered `readmitted`; failing a test, it
    /// stays excluded and the answer is `fault-still-present` (see [`super::probation`]).
    pub readmit_probation_samples: u32,
}

impl Default for FdiConfig {
    fn default() -> Self {
        Self {
            // 3.6e-4 persistent false alarms per hour per sensor type at 1 kHz; a 5σ step is still
            // declared within 10 samples with probability 1 − 2e-5.
            false_alarm_probability: 1e-10,
            persistence_k: 3,
            persistence_n: 5,
            isolation_margin: 10.0,
            parity_noise: ParityNoise::Configured,
            adaptive_window: 10_000,
            parity_offset_window: 60_000,
            motion_offset: false,
            mean_shift_window: 200,
            learning_samples: 1_000,
            saturation_samples: 5,
            stuck_samples: 20,
            noise_window: 200,
            noise_ratio: 25.0,
            stationary_window_s: 0.2,
            stationary_rate_spread_rps: 0.02,
            stationary_force_spread_mps2: 0.2,
            stationary_max_rate_rps: 0.05,
            reference_ratio: 3.0,
            motion_noise_fraction: 0.0,
            timing_skew_s: 0.0,
            readmit: ReadmitPolicy::Auto,
            readmit_after_samples: 1_000,
            readmit_probation_samples: 1_000,
        }
    }
}

/// Validated settings with the derived thresholds, ready for the per-sample path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FdiSettings {
    /// Exceedances needed within the last `persistence_n` samples to declare a fault.
    pub persistence_k: u32,
    /// Length of the persistence window, samples.
    pub persistence_n: u32,
    /// GLT isolation margin over the runner-up (see [`FdiConfig::isolation_margin`]).
    pub isolation_margin: f64,
    /// Which parity noise covariance the detector whitens with.
    pub parity_noise: ParityNoise,
    /// Averaging length of the adaptive noise estimate, samples.
    pub adaptive_window: u32,
    /// 0: no offset estimate.
    pub parity_offset_window: u32,
    /// See [`FdiConfig::motion_offset`].
    pub motion_offset: bool,
    /// 0: no mean-shift test.
    pub mean_shift_window: u32,
    /// χ² threshold of the mean-shift test for each parity dimension (index m; entry 0 unused).
    pub mean_shift_thresholds: [f64; MAX_PARITY + 1],
    /// Length of the learning phase (0 when neither the offset nor the adaptive noise is on).
    pub learning_samples: u32,
    /// Thresholds of the per-channel health checks.
    pub health: HealthSettings,
    /// Thresholds of the stationary detector behind the zero-rate/gravity reference.
    pub stationary: StationarySettings,
    /// Ratio of standard scores by which the isolated channel must stand out against the stationary
    /// reference (see [`FdiConfig::reference_ratio`]).
    pub reference_ratio: f64,
    /// See [`FdiConfig::motion_noise_fraction`].
    pub motion_noise_fraction: f64,
    /// [`FdiConfig::timing_skew_s`] in samples; set by the fuser, which knows the sample rate
    /// (0 from [`FdiConfig::settings`]).
    pub timing_skew_samples: f64,
    /// Whether a sensor type left without a solution re-admits its excluded channels by itself.
    pub readmit: ReadmitPolicy,
    /// Samples in a row an excluded channel must pass every check before it returns by itself.
    pub readmit_after_samples: u32,
    /// Samples a channel re-admitted by command is tested against the others, out of the
    /// solution, before it rejoins (see [`super::probation`]).
    pub readmit_probation_samples: u32,
    /// Per-sample exceedance probability α₁ behind the thresholds.
    pub exceedance_probability: f64,
    /// χ² threshold for each parity dimension (index m; entry 0 unused).
    pub thresholds: [f64; MAX_PARITY + 1],
    /// For each parity dimension m, E[T | T < threshold] / m for fault-free T ~ χ²(m): how much a
    /// covariance estimate that skips the samples above the threshold falls short (index 0
    /// unused). Equals P(m/2 + 1, x/2) / P(m/2, x/2) at the threshold x.
    pub truncation: [f64; MAX_PARITY + 1],
}

/// Longest stationary block, s.
pub const MAX_STATIONARY_WINDOW_S: f64 = 60.0;

fn positive(field: &str, v: f64) -> Result<(), ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(ConfigError::new(field, v, "must be finite and > 0"))
    }
}

fn at_least(field: &str, v: u32, min: u32) -> Result<(), ConfigError> {
    if v >= min {
        Ok(())
    } else {
        Err(ConfigError::new(field, v, format!("must be >= {min}")))
    }
}

impl FdiConfig {
    /// [`Self::settings_at`] at 1 kHz.
    pub fn settings(&self) -> Result<FdiSettings, ConfigError> {
        self.settings_at(1000.0)
    }

    /// Checks every field and derives the thresholds for an IMU rate of `rate_hz`. Errors name
    /// the field relative to this table (e.g. `persistence_k = 9: must be <= persistence_n (5)`).
    pub fn settings_at(&self, rate_hz: f64) -> Result<FdiSettings, ConfigError> {
        let (k, n) = (self.persistence_k, self.persistence_n);
        if !(1..=MAX_PERSISTENCE_WINDOW as u32).contains(&n) {
            return Err(ConfigError::new(
                "persistence_n",
                n,
                format!("must be in 1..={MAX_PERSISTENCE_WINDOW}"),
            ));
        }
        at_least("persistence_k", k, 1)?;
        if k > n {
            return Err(ConfigError::new(
                "persistence_k",
                k,
                format!("must be <= persistence_n ({n})"),
            ));
        }
        let alpha = self.false_alarm_probability;
        positive("false_alarm_probability", alpha)?;
        let alpha1 = exceedance_probability(alpha, k, n).ok_or_else(|| {
            ConfigError::new(
                "false_alarm_probability",
                alpha,
                format!("must be below what {k}-of-{n} persistence can reach (use a value < 1e-3)"),
            )
        })?;
        let mut thresholds = [f64::INFINITY; MAX_PARITY + 1];
        for (m, t) in thresholds.iter_mut().enumerate().skip(1) {
            *t = chi2_upper_quantile(m, alpha1)
                .map_err(|e| ConfigError::new("false_alarm_probability", alpha, e.to_string()))?;
        }
        // One mean-shift test per window is an independent try: the configured probability
        // applies to it as it stands.
        let mut mean_shift_thresholds = [f64::INFINITY; MAX_PARITY + 1];
        for (m, t) in mean_shift_thresholds.iter_mut().enumerate().skip(1) {
            *t = chi2_upper_quantile(m, alpha)
                .map_err(|e| ConfigError::new("false_alarm_probability", alpha, e.to_string()))?;
        }
        if self.mean_shift_window != 0 {
            at_least("mean_shift_window", self.mean_shift_window, 10)?;
        }
        if !(self.isolation_margin.is_finite() && self.isolation_margin >= 0.0) {
            return Err(ConfigError::new(
                "isolation_margin",
                self.isolation_margin,
                "must be finite and >= 0",
            ));
        }
        let mut truncation = [1.0; MAX_PARITY + 1];
        for (m, k) in truncation.iter_mut().enumerate().skip(1) {
            let half = thresholds[m] / 2.0;
            let a = m as f64 / 2.0;
            *k = regularized_gamma_p(a + 1.0, half) / regularized_gamma_p(a, half);
        }
        at_least("adaptive_window", self.adaptive_window, 10)?;
        if self.parity_offset_window != 0 {
            at_least("parity_offset_window", self.parity_offset_window, 10)?;
        } else if self.motion_offset {
            return Err(ConfigError::new(
                "motion_offset",
                true,
                "needs the parity offset (parity_offset_window > 0)",
            ));
        }
        let learns = self.parity_offset_window != 0 || self.parity_noise == ParityNoise::Adaptive;
        at_least("saturation_samples", self.saturation_samples, 1)?;
        at_least("stuck_samples", self.stuck_samples, 2)?;
        at_least("noise_window", self.noise_window, 10)?;
        if !(self.noise_ratio.is_finite() && self.noise_ratio > 1.0) {
            return Err(ConfigError::new(
                "noise_ratio",
                self.noise_ratio,
                "must be finite and > 1",
            ));
        }
        let w = self.stationary_window_s;
        if !(w.is_finite() && w > 0.0 && w <= MAX_STATIONARY_WINDOW_S) {
            return Err(ConfigError::new(
                "stationary_window_s",
                w,
                format!("must be in (0, {MAX_STATIONARY_WINDOW_S}] s"),
            ));
        }
        // Bounded by 60 s × 100 kHz, well inside u32.
        let stationary_window = (w * rate_hz).round() as u32;
        if stationary_window < 10 {
            return Err(ConfigError::new(
                "stationary_window_s",
                w,
                format!("must span at least 10 samples at device.imu_rate_hz = {rate_hz}"),
            ));
        }
        positive(
            "stationary_rate_spread_rps",
            self.stationary_rate_spread_rps,
        )?;
        positive(
            "stationary_force_spread_mps2",
            self.stationary_force_spread_mps2,
        )?;
        positive("stationary_max_rate_rps", self.stationary_max_rate_rps)?;
        if !(self.reference_ratio.is_finite() && self.reference_ratio >= 1.0) {
            return Err(ConfigError::new(
                "reference_ratio",
                self.reference_ratio,
                "must be finite and >= 1",
            ));
        }
        if !(self.motion_noise_fraction.is_finite()
            && (0.0..1.0).contains(&self.motion_noise_fraction))
        {
            return Err(ConfigError::new(
                "motion_noise_fraction",
                self.motion_noise_fraction,
                "must be in [0, 1)",
            ));
        }
        if !(self.timing_skew_s.is_finite() && (0.0..=1.0).contains(&self.timing_skew_s)) {
            return Err(ConfigError::new(
                "timing_skew_s",
                self.timing_skew_s,
                "must be in [0, 1] s",
            ));
        }
        at_least("readmit_after_samples", self.readmit_after_samples, 10)?;
        at_least(
            "readmit_probation_samples",
            self.readmit_probation_samples,
            10,
        )?;
        Ok(FdiSettings {
            readmit: self.readmit,
            readmit_after_samples: self.readmit_after_samples,
            readmit_probation_samples: self.readmit_probation_samples,
            motion_noise_fraction: self.motion_noise_fraction,
            timing_skew_samples: 0.0,
            persistence_k: k,
            persistence_n: n,
            isolation_margin: self.isolation_margin,
            parity_noise: self.parity_noise,
            adaptive_window: self.adaptive_window,
            parity_offset_window: self.parity_offset_window,
            motion_offset: self.motion_offset,
            mean_shift_window: self.mean_shift_window,
            mean_shift_thresholds,
            learning_samples: if learns { self.learning_samples } else { 0 },
            health: HealthSettings {
                saturation_samples: self.saturation_samples,
                rails: [
                    super::channel_health::COUNT_MIN,
                    super::channel_health::COUNT_MAX,
                ],
                stuck_samples: self.stuck_samples,
                noise_window: self.noise_window,
                noise_ratio: self.noise_ratio,
            },
            stationary: StationarySettings {
                window: stationary_window,
                rate_spread: self.stationary_rate_spread_rps,
                force_spread: self.stationary_force_spread_mps2,
                max_rate: self.stationary_max_rate_rps,
            },
            reference_ratio: self.reference_ratio,
            exceedance_probability: alpha1,
            thresholds,
            truncation,
        })
    }

    /// Checks every field; errors name the field relative to this table.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.settings().map(|_| ())
    }
}
