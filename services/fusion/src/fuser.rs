//! The gyro and accelerometer sides together: counts → SI (with temperature compensation) →
//! fault detection and isolation → weighted least squares over the channels in service.
//!
//! Each side is a [`SensorMonitor`]: it owns the solver and parity space of its active channel
//! set, rebuilt only when a channel is excluded or readmitted (rare). Exclusions latch; see
//! [`crate::fdi::monitor`]. The stationary detector spans both sides (it needs the fused rate and
//! specific force) and feeds their stationary references.
//!
//! **Fusion method** (`[fusion] method`): `wls` outputs the monitor's per-sample least-squares
//! solution; `kalman` feeds the same channels to a [`KalmanFuser`] (see [`crate::kalman`] for
//! when each is better), switched to the new channel set on every exclusion or readmission while
//! keeping its state, so a reconfiguration does not reset or glitch the estimate. Fault detection
//! always works on the raw channel values, independent of the method.
//!
//! **Rest bias** (`[fusion] rest_bias_s`): gyro channel biases from a start-up window at rest,
//! subtracted before parity and the solve; see [`crate::rest_bias`].

use crate::calibration::{Calibration, ChannelCalibration, MAX_TEMPERATURE_C, MIN_TEMPERATURE_C};
use crate::error::ConfigError;
use crate::fdi::channel_health::{COUNT_MAX, COUNT_MIN};
use crate::fdi::stationary::StationaryDetector;
use crate::fdi::{
    ChannelEvents, FdiConfig, FdiSettings, MonitorInput, ReadmitError, SensorEstimate,
    SensorMonitor, SensorStatus,
};
use crate::geometry::{Geometry, GeometryConfig, MAX_CHANNELS, channel_mask};
use crate::kalman::{FusionMethod, KalmanConfig, KalmanFuser};
use crate::rest_bias::{RestBias, RestBiasState};
use ipc_types::{FusedImu, RawImu, SensorType, fused_flags, status};
use serde::Deserialize;

/// Bit of the first accelerometer channel in the raw valid mask (bit i gyro i, bit 16 + i accel i).
pub const ACCEL_MASK_SHIFT: u32 = 16;

/// Default gyro channel noise σ: 0.01 °/s/√Hz over a 1 kHz bandwidth, in rad/s.
pub fn default_gyro_sigma_rps() -> f64 {
    0.01_f64.to_radians() * 1000_f64.sqrt()
}

/// Default accelerometer channel noise σ: 150 µg/√Hz over a 1 kHz bandwidth, in m/s².
pub fn default_accel_sigma_mps2() -> f64 {
    150e-6 * rins_earth::STANDARD_GRAVITY * 1000_f64.sqrt()
}

/// One value per sensor type.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PerSensor<T> {
    pub gyro: T,
    pub accel: T,
}

/// White-noise standard deviation of each channel at the sample rate, SI units.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(untagged)]
pub enum ChannelNoise {
    /// The same σ for every channel.
    Uniform(f64),
    /// One σ per channel (N entries).
    PerChannel(Vec<f64>),
}

/// Range of a channel noise σ (rad/s or m/s²).
const SIGMA_MIN: f64 = 1e-9;
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
#[derive(Debug, Clone, PartialEq, Deserialize)]
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

/// Fusion configuration. Defaults: the seed pyramid (n = 4, α = 28.7°, β0 = 45°) for both types,
/// the default channel noise, identity calibration, the default fault detection settings, WLS,
/// a 1 s rest-bias window at 1 kHz.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FusionConfig {
    pub geometry: PerSensor<GeometryConfig>,
    pub noise: NoiseConfig,
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
    fn kalman_settings(&self) -> Result<KalmanConfig, ConfigError> {
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

    fn fdi_settings(&self) -> Result<FdiSettings, ConfigError> {
        let mut settings = self.fdi.settings().map_err(|e| e.within("fdi"))?;
        settings.timing_skew_samples = self.fdi.timing_skew_s * self.sample_rate_hz;
        Ok(settings)
    }

    fn side_parts(
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

/// Fused body rate and specific force of one IMU frame, with the fault-detection status.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Fused {
    /// Body rate, FRD, rad/s (zeros when `!gyro_ok`).
    pub rate: [f64; 3],
    /// Specific force, FRD, m/s² (zeros when `!accel_ok`).
    pub specific_force: [f64; 3],
    /// Variance of each rate axis, (rad/s)².
    pub rate_var: [f64; 3],
    /// Variance of each specific-force axis, (m/s²)².
    pub specific_force_var: [f64; 3],
    /// At least three active, well-conditioned gyro channels.
    pub gyro_ok: bool,
    /// At least three active, well-conditioned accelerometer channels.
    pub accel_ok: bool,
    /// Gyro channels that entered the solution (bit i = channel i).
    pub gyro_mask: u32,
    /// Accelerometer channels that entered the solution (bit i = channel i).
    pub accel_mask: u32,
    /// Per-channel states, reasons and parity statistic of the gyros.
    pub gyro_status: SensorStatus,
    /// Per-channel states, reasons and parity statistic of the accelerometers.
    pub accel_status: SensorStatus,
    /// Channel state changes of this frame (for the log).
    pub events: ChannelEvents,
    /// The vehicle is judged stationary (stationary reference usable).
    pub stationary: bool,
    /// The per-channel gyro rest bias is still being measured (see [`crate::rest_bias`]).
    pub rest_bias_pending: bool,
}

impl Fused {
    /// [`FusedImu::flags`] bits: insufficient channels, a saturated block, detected-not-isolated
    /// faults, the rest bias still pending.
    pub fn flags(&self) -> u32 {
        let mut flags = 0;
        if !self.gyro_ok {
            flags |= fused_flags::GYRO_INSUFFICIENT;
        }
        if !self.accel_ok {
            flags |= fused_flags::ACCEL_INSUFFICIENT;
        }
        if self.gyro_status.detected_not_isolated {
            flags |= fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED;
        }
        if self.accel_status.detected_not_isolated {
            flags |= fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED;
        }
        if self.rest_bias_pending {
            flags |= fused_flags::GYRO_REST_BIAS_PENDING;
        }
        if self.gyro_status.block_saturated {
            flags |= fused_flags::GYRO_SATURATED;
        }
        if self.accel_status.block_saturated {
            flags |= fused_flags::ACCEL_SATURATED;
        }
        flags
    }

    /// Writes the fault-detection fields of `msg`: flags, per-channel states and reasons, test
    /// statistics. The estimate fields and the header are the caller's.
    pub fn write_fdi(&self, msg: &mut FusedImu) {
        msg.flags = self.flags();
        msg.gyro_state = self.gyro_status.states.map(|s| s as u8);
        msg.accel_state = self.accel_status.states.map(|s| s as u8);
        msg.gyro_reason = self.gyro_status.reasons.map(|r| r as u8);
        msg.accel_reason = self.accel_status.reasons.map(|r| r as u8);
        msg.gyro_test_statistic = self.gyro_status.test_statistic as f32;
        msg.accel_test_statistic = self.accel_status.test_statistic as f32;
    }
}

/// One raw frame as slices: what [`ImuFuser::fuse_sample`] needs.
#[derive(Debug, Clone, Copy, Default)]
pub struct ImuSample<'a> {
    /// Gyro counts, channel i at index i (missing channels count as invalid).
    pub gyro_counts: &'a [i16],
    /// Accelerometer counts.
    pub accel_counts: &'a [i16],
    /// Bit i gyro channel i valid, bit 16 + i accel channel i valid.
    pub valid_mask: u32,
    /// Device status bits ([`ipc_types::status`]).
    pub status: u32,
    /// Module temperatures, °C (empty: no compensation, no temperature check).
    pub temperatures_c: &'a [f32],
}

/// Combines the redundant gyro and accelerometer channels into body rate and specific force,
/// detecting, isolating and excluding faulty channels.
#[derive(Debug, Clone)]
pub struct ImuFuser {
    gyro: RedundantSensor,
    accel: RedundantSensor,
    stationary: StationaryDetector,
    rest_bias: RestBias,
}

impl ImuFuser {
    /// Builds the fuser. `gyro_lsb` (rad/s per count) and `accel_lsb` (m/s² per count) come from
    /// the ADC full scale of the sensor block.
    pub fn new(config: &FusionConfig, gyro_lsb: f64, accel_lsb: f64) -> Result<Self, ConfigError> {
        let settings = config.fdi_settings()?;
        let kalman = config.kalman_settings()?;
        let rest_window = config.rest_bias_samples()?;
        let gyro = RedundantSensor::new(config, SensorType::Gyro, gyro_lsb, settings, &kalman)?;
        let accel = RedundantSensor::new(config, SensorType::Accel, accel_lsb, settings, &kalman)?;
        let rest_bias = RestBias::new(rest_window, gyro.geometry.n(), settings.stationary);
        Ok(Self {
            gyro,
            accel,
            stationary: StationaryDetector::new(settings.stationary),
            rest_bias,
        })
    }

    /// Fuses one frame without device status or temperatures. `valid_mask`: bit i gyro channel
    /// i, bit 16 + i accel channel i; invalid channels and channels beyond the end of a counts
    /// slice are excluded (and stay excluded, see [`Self::readmit`]).
    pub fn fuse(&mut self, gyro_counts: &[i16], accel_counts: &[i16], valid_mask: u32) -> Fused {
        self.fuse_sample(&ImuSample {
            gyro_counts,
            accel_counts,
            valid_mask,
            ..ImuSample::default()
        })
    }

    /// Fuses one raw IPC frame (counts sliced to the configured channel counts).
    pub fn fuse_raw(&mut self, raw: &RawImu) -> Fused {
        let n_temperature = usize::from(raw.n_temperature).min(raw.temperature_c.len());
        self.fuse_sample(&ImuSample {
            gyro_counts: &raw.gyro_counts[..self.gyro.geometry.n()],
            accel_counts: &raw.accel_counts[..self.accel.geometry.n()],
            valid_mask: raw.valid_mask,
            status: raw.status,
            temperatures_c: &raw.temperature_c[..n_temperature],
        })
    }

    /// Fuses one frame. Allocates only when a channel is excluded (reconfiguration).
    pub fn fuse_sample(&mut self, sample: &ImuSample) -> Fused {
        let device_error = sample.status & status::DEVICE_ERROR != 0;
        let stationary = self.stationary.is_stationary();
        let mut events = ChannelEvents::EMPTY;
        let frame = FrameContext {
            temperatures_c: sample.temperatures_c,
            device_error,
            stationary,
        };
        let (g, gyro_status) = self.gyro.fuse(
            sample.gyro_counts,
            sample.valid_mask,
            &frame,
            Some(&mut self.rest_bias),
            &mut events,
        );
        let (a, accel_status) = self.accel.fuse(
            sample.accel_counts,
            sample.valid_mask >> ACCEL_MASK_SHIFT,
            &frame,
            None,
            &mut events,
        );
        if let Some(verdict) = self.stationary.push(&g.x, &a.x, g.ok && a.ok) {
            self.gyro.monitor.end_block(verdict);
            self.accel.monitor.end_block(verdict);
        }
        if let Some(bias) = self.rest_bias.end_sample(&g.x, &a.x, g.ok && a.ok) {
            self.gyro.monitor.subtract_channel_biases(bias);
            // The filter's state holds the biased rate: start it afresh on the corrected values.
            if let Some(kf) = self.gyro.kalman.as_mut() {
                kf.reset();
            }
        }
        Fused {
            rate: g.x,
            specific_force: a.x,
            rate_var: g.var,
            specific_force_var: a.var,
            gyro_ok: g.ok,
            accel_ok: a.ok,
            gyro_mask: g.mask,
            accel_mask: a.mask,
            gyro_status,
            accel_status,
            events,
            stationary,
            rest_bias_pending: self.rest_bias.state() == RestBiasState::Collecting,
        }
    }

    /// Returns an excluded channel to service — by explicit command only; exclusions otherwise
    /// latch (see [`crate::fdi::monitor`]). `Ok(false)` when the channel was not excluded.
    pub fn readmit(&mut self, sensor: SensorType, channel: usize) -> Result<bool, ReadmitError> {
        self.monitor_mut(sensor).readmit(channel)
    }

    /// The fault-detection state of one sensor type.
    pub fn monitor(&self, sensor: SensorType) -> &SensorMonitor {
        match sensor {
            SensorType::Gyro => &self.gyro.monitor,
            SensorType::Accel => &self.accel.monitor,
        }
    }

    fn monitor_mut(&mut self, sensor: SensorType) -> &mut SensorMonitor {
        match sensor {
            SensorType::Gyro => &mut self.gyro.monitor,
            SensorType::Accel => &mut self.accel.monitor,
        }
    }

    /// The start-up window at rest was found and its per-channel gyro biases are being subtracted.
    pub fn rest_bias_estimated(&self) -> bool {
        self.rest_bias.state() == RestBiasState::Estimated
    }

    /// Where the start-up gyro bias estimate stands (collecting, estimated, not at rest, disabled).
    pub fn rest_bias_state(&self) -> RestBiasState {
        self.rest_bias.state()
    }

    /// The per-channel gyro biases subtracted, rad/s (N entries; zeros unless estimated).
    pub fn gyro_rest_bias(&self) -> &[f64] {
        self.rest_bias.bias()
    }

    /// How the channels are fused.
    pub fn method(&self) -> FusionMethod {
        if self.gyro.kalman.is_some() {
            FusionMethod::Kalman
        } else {
            FusionMethod::Wls
        }
    }

    /// Gyro axes.
    pub fn gyro_geometry(&self) -> &Geometry {
        &self.gyro.geometry
    }

    /// Accelerometer axes.
    pub fn accel_geometry(&self) -> &Geometry {
        &self.accel.geometry
    }
}

/// What both sides of one frame share.
#[derive(Debug, Clone, Copy)]
struct FrameContext<'a> {
    /// Module temperatures, °C.
    temperatures_c: &'a [f32],
    /// The device reports an error.
    device_error: bool,
    /// The vehicle is judged stationary now.
    stationary: bool,
}

/// One sensor type: geometry, calibration, its fault monitor and, with the Kalman method, the
/// filter over the monitor's active channels.
#[derive(Debug, Clone)]
struct RedundantSensor {
    geometry: Geometry,
    calibration: Calibration,
    monitor: SensorMonitor,
    /// Channel noise σ² including quantisation (first N entries).
    variances: [f64; MAX_CHANNELS],
    kalman: Option<KalmanFuser>,
}

impl RedundantSensor {
    fn new(
        config: &FusionConfig,
        sensor: SensorType,
        lsb: f64,
        settings: FdiSettings,
        kalman: &KalmanConfig,
    ) -> Result<Self, ConfigError> {
        let lsb_field = match sensor {
            SensorType::Gyro => "gyro_lsb",
            SensorType::Accel => "accel_lsb",
        };
        if !(lsb.is_finite() && lsb > 0.0) {
            return Err(ConfigError::new(lsb_field, lsb, "must be finite and > 0"));
        }
        let (geometry, mut variances, calibration) = config.side_parts(sensor)?;
        let n = geometry.n();
        let calibration = Calibration::new(calibration, n, lsb)
            .map_err(|e| e.within(sensor.name()).within("calibration"))?;
        // The converter adds its quantisation noise, (step)²/12 with the step in SI units, to the
        // sensor's own: significant at 1–2 lsb of noise, where it raises the variance by 2–6 %.
        for (i, v) in variances.iter_mut().enumerate().take(n) {
            let step = calibration.apply(i, 1) - calibration.apply(i, 0);
            *v += step * step / 12.0;
        }
        let rail_values = std::array::from_fn(|i| {
            [
                calibration.apply(i, COUNT_MIN),
                calibration.apply(i, COUNT_MAX),
            ]
        });
        let monitor = SensorMonitor::new(sensor, geometry, variances, rail_values, settings);
        // The full geometry passed the conditioning check, so this only fails on a logic error.
        if monitor.solver().is_none() {
            return Err(ConfigError::new(
                format!("geometry.{}", sensor.name()),
                format!("{n} axes"),
                "no least-squares solution for the full channel set",
            ));
        }
        let kalman = match config.method {
            FusionMethod::Wls => None,
            FusionMethod::Kalman => {
                let (q, field) = match sensor {
                    SensorType::Gyro => (kalman.process_noise.gyro, "process_noise.gyro"),
                    SensorType::Accel => (kalman.process_noise.accel, "process_noise.accel"),
                };
                let kf = KalmanFuser::new(
                    &geometry,
                    geometry.full_mask(),
                    &variances[..n],
                    kalman.sample_period_s,
                    q,
                )
                .map_err(|e| ConfigError::new(format!("kalman.{field}"), q, e.to_string()))?;
                Some(kf)
            }
        };
        Ok(Self {
            geometry,
            calibration,
            monitor,
            variances,
            kalman,
        })
    }

    /// One side of one frame. `rest_bias`: the start-up bias estimate of this side, if any
    /// (collects the calibrated values, later subtracts the biases before parity and the solve).
    fn fuse(
        &mut self,
        counts: &[i16],
        valid: u32,
        frame: &FrameContext,
        rest_bias: Option<&mut RestBias>,
        events: &mut ChannelEvents,
    ) -> (SensorEstimate, SensorStatus) {
        let FrameContext {
            temperatures_c,
            device_error,
            stationary,
        } = *frame;
        let n = self.geometry.n();
        let valid = valid & channel_mask(n.min(counts.len()));
        let mut z = [f64::NAN; MAX_CHANNELS];
        let mut temperature_suspect = 0;
        if temperatures_c.is_empty() {
            self.calibration.apply_all(counts, &mut z);
        } else {
            self.calibration
                .apply_all_with_temperature(counts, temperatures_c, &mut z);
            for i in 0..n {
                let reading = temperatures_c.get(self.calibration.temperature_sensor(i));
                if reading.is_some_and(|&t| {
                    !(f64::from(t).is_finite()
                        && (MIN_TEMPERATURE_C..=MAX_TEMPERATURE_C).contains(&f64::from(t)))
                }) {
                    temperature_suspect |= 1 << i;
                }
            }
        }
        if let Some(rest_bias) = rest_bias {
            rest_bias.apply(&mut z, valid);
        }
        let input = MonitorInput {
            counts,
            z: &z,
            valid,
            device_error,
            temperature_suspect,
        };
        let (estimate, status) = self.monitor.step(&input, stationary, events);
        let estimate = match self.kalman.as_mut() {
            Some(kf) => Self::filter(kf, &self.geometry, &self.variances, estimate, &z),
            None => estimate,
        };
        (estimate, status)
    }

    /// The Kalman estimate over the channels the monitor solved with, following its channel set.
    fn filter(
        kf: &mut KalmanFuser,
        geometry: &Geometry,
        variances: &[f64; MAX_CHANNELS],
        wls: SensorEstimate,
        z: &[f64; MAX_CHANNELS],
    ) -> SensorEstimate {
        let not_ok = SensorEstimate {
            mask: wls.mask,
            ..SensorEstimate::default()
        };
        if !wls.ok {
            kf.reset();
            return not_ok;
        }
        if kf.mask() != wls.mask
            && kf
                .set_channels(geometry, wls.mask, &variances[..geometry.n()])
                .is_err()
        {
            kf.reset();
            return not_ok;
        }
        let (x, var) = kf.update(z);
        SensorEstimate {
            x,
            var,
            ok: true,
            mask: wls.mask,
        }
    }
}
