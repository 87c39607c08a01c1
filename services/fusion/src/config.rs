//! The `[fusion]` table: sensor geometries, channel noise, calibration, fault detection, the
//! fusion method and the start-up rest-bias window, with the checks that name the offending field.
//!
//! [`FusionConfig::validate`] runs every check the fuser's constructor runs, so a configuration it
//! accepts always builds an [`crate::ImuFuser`].

use crate::calibration::ChannelCalibration;
use crate::error::ConfigError;
use crate::fdi::{FdiConfig, FdiSettings};
use crate::geometry::{Geometry, GeometryConfig, MAX_CHANNELS};
use crate::kalman::{FusionMethod, KalmanConfig};
use ipc_types::SensorType;
use serde::{Deserialize, Serialize};

/// Default gyro channel noise σ: 0.01 °/s/√Hz over a 1 kHz bandwidth, in rad/s.
pub fn default_gyro_sigma_rps() -> f64 {
    0.01_f64.to_radians() * 1000_f64.sqrt()
}

/// Default accelerometer channel noise σ: 150 µg/√Hz over a 1 kHz bandwidth, in m/s².
pub fn default_accel_sigma_mps2() -> f64 {
    150e-6 * rins_earth::STANDARD_GRAVITY * 1000_f64.sqrt()
}

/// One value per sensor type.
#[derive(Debug, Clone, PartialEq, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerSensor<T> {
    /// The gyros' value.
    pub gyro: T,
    /// The accelerometers' value.
    pub accel: T,
}

/// White-noise standard deviation of each channel at the sample rate, SI units.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum ChannelNoise {
    /// The same σ for every channel.
    Uniform(f64),
    /// One σ per channel (N entries).
    PerChannel(Vec<f64>),
}

/// Smallest accepted channel noise σ (rad/s or m/s²).
const SIGMA_MIN: f64 = 1e-9;
/// Largest accepted channel noise σ (rad/s or m/s²).
const SIGMA_MAX: f64 = 1e3;

impl ChannelNoise {
    /// Per-channel variances σ_i² for `n` channels. Errors name `[i]` or the whole field.
    pub fn variances(&self, n: usize) -> Result<[f64; MAX_CHANNELS], ConfigError> {
        // Bounded so that σ² and the weights 1/σ² stay ordinary numbers: beyond them the
        // weighted least squares loses its solution (1e308² overflows, 1e-300² underflows).
        let check = |field: String, s: f64| {
            if (SIGMA_MIN..=SIGMA_MAX).contains(&s) {
                Ok(s * s)
            } else {
                // Very large or small values as written (1e308), not in 300 digits.
                let shown = if s != 0.0 && !(1e-4..1e6).contains(&s.abs()) {
                    format!("{s:e}")
                } else {
                    s.to_string()
                };
                Err(ConfigError::new(
                    field,
                    shown,
                    format!("must be in [{SIGMA_MIN:e}, {SIGMA_MAX:e}]"),
                ))
            }
        };
        let mut out = [0.0; MAX_CHANNELS];
        match self {
            ChannelNoise::Uniform(s) => {
                let v = check(String::new(), *s)?;
                out.iter_mut().take(n).for_each(|o| *o = v);
            }
            ChannelNoise::PerChannel(list) => {
                if list.len() != n {
                    return Err(ConfigError::new(
                        "",
                        format!("{} entries", list.len()),
                        format!("must be one number or have {n} entries (one per channel)"),
                    ));
                }
                for (i, (o, s)) in out.iter_mut().zip(list).enumerate() {
                    *o = check(format!("[{i}]"), *s)?;
                }
            }
        }
        Ok(out)
    }
}

/// Channel noise of both sensor types.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseConfig {
    /// Gyro channel σ, rad/s.
    pub gyro_sigma_rps: ChannelNoise,
    /// Accelerometer channel σ, m/s².
    pub accel_sigma_mps2: ChannelNoise,
}

impl Default for NoiseConfig {
    fn default() -> Self {
        Self {
            gyro_sigma_rps: ChannelNoise::Uniform(default_gyro_sigma_rps()),
            accel_sigma_mps2: ChannelNoise::Uniform(default_accel_sigma_mps2()),
        }
    }
}

/// Default length of the start-up gyro bias window, s.
pub const DEFAULT_REST_BIAS_S: f64 = 1.0;
/// Default nominal IMU sample rate, Hz.
pub const DEFAULT_SAMPLE_RATE_HZ: f64 = 1000.0;
/// Accepted nominal sample rates, Hz.
pub const SAMPLE_RATE_RANGE_HZ: std::ops::RangeInclusive<f64> = 1.0..=100_000.0;
/// Fewest samples of a non-zero rest-bias window (the stationary criterion needs a spread).
pub const MIN_REST_BIAS_SAMPLES: u32 = 10;
/// Longest rest-bias window, s.
pub const MAX_REST_BIAS_S: f64 = 600.0;

/// Fusion configuration. Defaults: the four-axis pyramid (n = 4, α = 28.7°, β0 = 45°) for both types,
/// the default channel noise, identity calibration, the default fault detection settings, WLS,
/// a 1 s rest-bias window at 1 kHz.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct FusionConfig {
    /// Sensitive axes of each sensor type (`[fusion.geometry.gyro]`, `[fusion.geometry.accel]`).
    pub geometry: PerSensor<GeometryConfig>,
    /// White-noise σ of every channel (`[fusion.noise]`).
    pub noise: NoiseConfig,
    /// Per-channel bias, scale and temperature terms (`[fusion.calibration.*]`).
    pub calibration: PerSensor<ChannelCalibration>,
    /// Fault detection, isolation and reconfiguration (`[fusion.fdi]`).
    pub fdi: FdiConfig,
    /// How the channels become a 3-axis estimate: `"wls"` (default) or `"kalman"`.
    #[serde(default)]
    pub method: FusionMethod,
    /// Settings of the Kalman method (`[fusion.kalman]`); unused with WLS.
    pub kalman: KalmanConfig,
    /// Length of the start-up window over which per-channel gyro biases are estimated at rest, s
    /// (0 disables it); see [`crate::rest_bias`].
    pub rest_bias_s: f64,
    /// Nominal IMU sample rate, Hz: turns `rest_bias_s` into samples. With the Kalman method it
    /// must agree with `kalman.sample_period_s`.
    pub sample_rate_hz: f64,
}

impl Default for FusionConfig {
    fn default() -> Self {
        Self {
            geometry: PerSensor::default(),
            noise: NoiseConfig::default(),
            calibration: PerSensor::default(),
            fdi: FdiConfig::default(),
            method: FusionMethod::default(),
            kalman: KalmanConfig::default(),
            rest_bias_s: DEFAULT_REST_BIAS_S,
            sample_rate_hz: DEFAULT_SAMPLE_RATE_HZ,
        }
    }
}

impl FusionConfig {
    /// Checks every field; errors name the field path (e.g. `geometry.gyro.alpha_deg`,
    /// `fdi.persistence_k`) and value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for sensor in [SensorType::Gyro, SensorType::Accel] {
            self.side_parts(sensor)?;
        }
        self.fdi_settings()?;
        self.kalman_settings()?;
        self.rest_bias_samples().map(|_| ())
    }

    /// The Kalman settings, checked (also when unused: a config must not hide a bad value).
    pub(crate) fn kalman_settings(&self) -> Result<KalmanConfig, ConfigError> {
        self.kalman.validate().map_err(|e| e.within("kalman"))?;
        if self.method == FusionMethod::Kalman {
            // One nominal rate for the whole fuser: the filter's period must be its inverse.
            self.checked_sample_rate()?;
            let product = self.kalman.sample_period_s * self.sample_rate_hz;
            if (product - 1.0).abs() > 1e-6 {
                return Err(ConfigError::new(
                    "kalman.sample_period_s",
                    self.kalman.sample_period_s,
                    format!(
                        "must be 1 / sample_rate_hz = {} s with method = \"kalman\"",
                        1.0 / self.sample_rate_hz
                    ),
                ));
            }
        }
        Ok(self.kalman)
    }

    /// The nominal sample rate, checked against [`SAMPLE_RATE_RANGE_HZ`].
    fn checked_sample_rate(&self) -> Result<f64, ConfigError> {
        let rate = self.sample_rate_hz;
        if !SAMPLE_RATE_RANGE_HZ.contains(&rate) {
            return Err(ConfigError::new(
                "sample_rate_hz",
                rate,
                format!(
                    "must be in {}..={} Hz",
                    SAMPLE_RATE_RANGE_HZ.start(),
                    SAMPLE_RATE_RANGE_HZ.end()
                ),
            ));
        }
        Ok(rate)
    }

    /// Length of the rest-bias window in samples (0: disabled).
    pub fn rest_bias_samples(&self) -> Result<u32, ConfigError> {
        let s = self.rest_bias_s;
        if !(s.is_finite() && (0.0..=MAX_REST_BIAS_S).contains(&s)) {
            return Err(ConfigError::new(
                "rest_bias_s",
                s,
                format!("must be in 0..={MAX_REST_BIAS_S} s (0 disables it)"),
            ));
        }
        if s == 0.0 {
            return Ok(0);
        }
        let rate = self.checked_sample_rate()?;
        // Bounded by 600 s × 100 kHz, well inside u32.
        let samples = (s * rate).round() as u32;
        if samples < MIN_REST_BIAS_SAMPLES {
            return Err(ConfigError::new(
                "rest_bias_s",
                s,
                format!(
                    "must span at least {MIN_REST_BIAS_SAMPLES} samples at sample_rate_hz = {rate} (or be 0)"
                ),
            ));
        }
        Ok(samples)
    }

    /// The validated fault-detection settings, with the timing skew turned into samples.
    pub(crate) fn fdi_settings(&self) -> Result<FdiSettings, ConfigError> {
        let mut settings = self.fdi.settings().map_err(|e| e.within("fdi"))?;
        settings.timing_skew_samples = self.fdi.timing_skew_s * self.sample_rate_hz;
        Ok(settings)
    }

    /// Geometry, channel variances and calibration of one sensor type, each checked; errors name
    /// the field path within `[fusion]`.
    pub(crate) fn side_parts(
        &self,
        sensor: SensorType,
    ) -> Result<(Geometry, [f64; MAX_CHANNELS], &ChannelCalibration), ConfigError> {
        let (geometry, noise, noise_field, calibration) = match sensor {
            SensorType::Gyro => (
                &self.geometry.gyro,
                &self.noise.gyro_sigma_rps,
                "noise.gyro_sigma_rps",
                &self.calibration.gyro,
            ),
            SensorType::Accel => (
                &self.geometry.accel,
                &self.noise.accel_sigma_mps2,
                "noise.accel_sigma_mps2",
                &self.calibration.accel,
            ),
        };
        let geometry = geometry
            .build()
            .map_err(|e| e.within(sensor.name()).within("geometry"))?;
        let variances = noise
            .variances(geometry.n())
            .map_err(|e| e.within(noise_field))?;
        calibration
            .validate(geometry.n())
            .map_err(|e| e.within(sensor.name()).within("calibration"))?;
        Ok((geometry, variances, calibration))
    }
}
