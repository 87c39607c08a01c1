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

/// Default gyro noise density (angle random walk), °/s/√Hz.
pub const DEFAULT_GYRO_NOISE_DENSITY_DPS_RTHZ: f64 = 0.01;
/// Default accelerometer noise density (velocity random walk), µg/√Hz.
pub const DEFAULT_ACCEL_NOISE_DENSITY_UG_RTHZ: f64 = 150.0;

/// A gyro noise density in °/s/√Hz, in rad/s/√Hz.
pub fn gyro_density_si(dps_rthz: f64) -> f64 {
    dps_rthz.to_radians()
}

/// An accelerometer noise density in µg/√Hz, in m/s²/√Hz.
pub fn accel_density_si(ug_rthz: f64) -> f64 {
    ug_rthz * 1e-6 * rins_earth::STANDARD_GRAVITY
}

/// The white-noise σ of one sample of a channel of noise density `density` (SI units per √Hz)
/// sampled at `rate_hz`: density · √rate, as the simulator draws it (for a one-sided density
/// band-limited at Nyquist it would be √(rate/2): this errs on the side of a larger σ). The
/// converter's quantisation, (step)²/12, is added by the fuser, which knows the calibrated step.
pub fn per_sample_sigma(density: f64, rate_hz: f64) -> f64 {
    density * rate_hz.sqrt()
}

/// The per-sample gyro σ of the default density at 1 kHz, rad/s (0.005519).
pub fn default_gyro_sigma_rps() -> f64 {
    per_sample_sigma(gyro_density_si(DEFAULT_GYRO_NOISE_DENSITY_DPS_RTHZ), 1000.0)
}

/// The per-sample accelerometer σ of the default density at 1 kHz, m/s² (0.046517).
pub fn default_accel_sigma_mps2() -> f64 {
    per_sample_sigma(
        accel_density_si(DEFAULT_ACCEL_NOISE_DENSITY_UG_RTHZ),
        1000.0,
    )
}

/// What `[device]` says about the sensor block that fusion needs: not a `[fusion]` key (the
/// deployment sets it from `device.imu_rate_hz` and `device.converter_bits`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuBlock {
    /// The block's output rate, Hz: turns densities into per-sample σ, seconds into samples, and
    /// is the Kalman filter's period.
    pub imu_rate_hz: f64,
    /// The converter's resolution, bits: its rails are −2^(bits−1) and 2^(bits−1) − 1.
    pub converter_bits: u8,
}

impl Default for ImuBlock {
    fn default() -> Self {
        Self {
            imu_rate_hz: DEFAULT_SAMPLE_RATE_HZ,
            converter_bits: 12,
        }
    }
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

/// White-noise density of each channel, in the unit its key names.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum ChannelNoise {
    /// The same density for every channel.
    Uniform(f64),
    /// One density per channel (N entries).
    PerChannel(Vec<f64>),
}

/// Smallest accepted per-sample σ (rad/s or m/s²).
const SIGMA_MIN: f64 = 1e-9;
/// Largest accepted per-sample σ (rad/s or m/s²).
const SIGMA_MAX: f64 = 1e3;
/// Smallest accepted density, in the key's unit.
const DENSITY_MIN: f64 = 1e-9;
/// Largest accepted density, in the key's unit (a vibrating airframe's accelerometers reach a
/// few thousand µg/√Hz).
const DENSITY_MAX: f64 = 1e6;

impl ChannelNoise {
    /// Per-channel per-sample variances σ_i² for `n` channels, σ_i = value_i · `to_sigma`
    /// (the unit conversion and √rate of [`per_sample_sigma`]). Errors name `[i]` or the whole
    /// field, with the value as written.
    pub fn variances(&self, n: usize, to_sigma: f64) -> Result<[f64; MAX_CHANNELS], ConfigError> {
        // Bounded so that σ² and the weights 1/σ² stay ordinary numbers: beyond them the
        // weighted least squares loses its solution (1e308² overflows, 1e-300² underflows).
        let check = |field: String, s: f64| {
            // Very large or small values as written (1e308), not in 300 digits.
            let shown = |v: f64| {
                if v != 0.0 && !(1e-4..1e6).contains(&v.abs()) {
                    format!("{v:e}")
                } else {
                    v.to_string()
                }
            };
            if !(DENSITY_MIN..=DENSITY_MAX).contains(&s) {
                return Err(ConfigError::new(
                    field,
                    shown(s),
                    format!("must be in [{DENSITY_MIN:e}, {DENSITY_MAX:e}]"),
                ));
            }
            let sigma = s * to_sigma;
            if !(SIGMA_MIN..=SIGMA_MAX).contains(&sigma) {
                return Err(ConfigError::new(
                    field,
                    shown(s),
                    format!(
                        "gives a per-sample σ of {sigma:.3e} at the IMU rate: must be in [{SIGMA_MIN:e}, {SIGMA_MAX:e}]"
                    ),
                ));
            }
            Ok(sigma * sigma)
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

/// Channel noise of both sensor types, as datasheets give it: a density, whatever the rate.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct NoiseConfig {
    /// Gyro noise density (angle random walk), °/s/√Hz.
    pub gyro_noise_density_dps_rthz: ChannelNoise,
    /// Accelerometer noise density (velocity random walk), µg/√Hz.
    pub accel_noise_density_ug_rthz: ChannelNoise,
}

impl Default for NoiseConfig {
    fn default() -> Self {
        Self {
            gyro_noise_density_dps_rthz: ChannelNoise::Uniform(DEFAULT_GYRO_NOISE_DENSITY_DPS_RTHZ),
            accel_noise_density_ug_rthz: ChannelNoise::Uniform(DEFAULT_ACCEL_NOISE_DENSITY_UG_RTHZ),
        }
    }
}

impl NoiseConfig {
    /// The densities whose per-sample σ at `rate_hz` are `gyro_sigma_rps` and `accel_sigma_mps2`
    /// (for experiments stated in per-sample σ).
    pub fn from_per_sample_sigma(gyro_sigma_rps: f64, accel_sigma_mps2: f64, rate_hz: f64) -> Self {
        let root = rate_hz.sqrt();
        Self {
            gyro_noise_density_dps_rthz: ChannelNoise::Uniform(
                gyro_sigma_rps / gyro_density_si(1.0) / root,
            ),
            accel_noise_density_ug_rthz: ChannelNoise::Uniform(
                accel_sigma_mps2 / accel_density_si(1.0) / root,
            ),
        }
    }
}

/// Default length of the start-up gyro bias window, s.
pub const DEFAULT_REST_BIAS_S: f64 = 1.0;
/// Default IMU sample rate, Hz.
pub const DEFAULT_SAMPLE_RATE_HZ: f64 = 1000.0;
/// Accepted IMU sample rates, Hz.
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
    /// White-noise density of every channel (`[fusion.noise]`).
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
    /// The sensor block's rate and converter, from `[device]` (not read from `[fusion]`).
    #[serde(skip)]
    pub block: ImuBlock,
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
            block: ImuBlock::default(),
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
        self.checked_sample_rate()?;
        Ok(self.kalman)
    }

    /// The IMU sample period, s: the Kalman filter's step.
    pub fn sample_period_s(&self) -> f64 {
        1.0 / self.block.imu_rate_hz
    }

    /// The IMU rate and converter bits, checked against [`SAMPLE_RATE_RANGE_HZ`] and
    /// [`crate::fdi::channel_health::CONVERTER_BITS`].
    fn checked_sample_rate(&self) -> Result<f64, ConfigError> {
        let rate = self.block.imu_rate_hz;
        if !SAMPLE_RATE_RANGE_HZ.contains(&rate) {
            return Err(ConfigError::new(
                "device.imu_rate_hz",
                rate,
                format!(
                    "must be in {}..={} Hz",
                    SAMPLE_RATE_RANGE_HZ.start(),
                    SAMPLE_RATE_RANGE_HZ.end()
                ),
            ));
        }
        let bits = crate::fdi::channel_health::CONVERTER_BITS;
        if !bits.contains(&self.block.converter_bits) {
            return Err(ConfigError::new(
                "device.converter_bits",
                self.block.converter_bits,
                format!("must be in {}..={}", bits.start(), bits.end()),
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
                    "must span at least {MIN_REST_BIAS_SAMPLES} samples at device.imu_rate_hz = {rate} (or be 0)"
                ),
            ));
        }
        Ok(samples)
    }

    /// The validated fault-detection settings, with the timing skew turned into samples.
    pub(crate) fn fdi_settings(&self) -> Result<FdiSettings, ConfigError> {
        let rate = self.checked_sample_rate()?;
        let mut settings = self.fdi.settings_at(rate).map_err(|e| e.within("fdi"))?;
        settings.timing_skew_samples = self.fdi.timing_skew_s * rate;
        settings.health.rails = crate::fdi::channel_health::count_rails(self.block.converter_bits);
        Ok(settings)
    }

    /// The per-sample white-noise σ of each channel of `sensor` (from its density at the IMU
    /// rate, before the converter's quantisation), SI units; errors name the field.
    pub fn channel_sigmas(&self, sensor: SensorType) -> Result<Vec<f64>, ConfigError> {
        let (geometry, variances, _) = self.side_parts(sensor)?;
        Ok(variances[..geometry.n()].iter().map(|v| v.sqrt()).collect())
    }

    /// Geometry, per-sample white-noise variances (from the densities at the IMU rate) and calibration of one sensor type, each checked; errors name
    /// the field path within `[fusion]`.
    pub(crate) fn side_parts(
        &self,
        sensor: SensorType,
    ) -> Result<(Geometry, [f64; MAX_CHANNELS], &ChannelCalibration), ConfigError> {
        let (geometry, noise, noise_field, unit_to_si, calibration) = match sensor {
            SensorType::Gyro => (
                &self.geometry.gyro,
                &self.noise.gyro_noise_density_dps_rthz,
                "noise.gyro_noise_density_dps_rthz",
                gyro_density_si(1.0),
                &self.calibration.gyro,
            ),
            SensorType::Accel => (
                &self.geometry.accel,
                &self.noise.accel_noise_density_ug_rthz,
                "noise.accel_noise_density_ug_rthz",
                accel_density_si(1.0),
                &self.calibration.accel,
            ),
        };
        let rate = self.checked_sample_rate()?;
        let geometry = geometry
            .build()
            .map_err(|e| e.within(sensor.name()).within("geometry"))?;
        let variances = noise
            .variances(geometry.n(), per_sample_sigma(unit_to_si, rate))
            .map_err(|e| e.within(noise_field))?;
        calibration
            .validate(geometry.n())
            .map_err(|e| e.within(sensor.name()).within("calibration"))?;
        Ok((geometry, variances, calibration))
    }
}
