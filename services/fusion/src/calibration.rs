//! ADC counts to SI units per channel, with temperature compensation (docs/design.md §6.1):
//!
//! ```text
//! bias_i(T)  = bias_i + bias_per_c_i · (T − T_ref)
//! scale_i(T) = scale_i · (1 + scale_ppm_per_c_i · 1e-6 · (T − T_ref))
//! value      = (counts · lsb − bias_i(T)) / scale_i(T)
//! ```
//!
//! T is the reading of the module temperature sensor the channel is mounted next to. It is clamped
//! to the calibrated range [`MIN_TEMPERATURE_C`]..=[`MAX_TEMPERATURE_C`] (the model is not
//! extrapolated), and a missing or non-finite reading falls back to T_ref, i.e. no compensation:
//! flagging such a temperature is the channel-health monitor's job, and a NaN here would poison
//! every estimate that uses the channel.

use crate::error::ConfigError;
use crate::geometry::MAX_CHANNELS;
use ipc_types::MAX_TEMPERATURES;
use serde::{Deserialize, Serialize};

/// Lowest temperature the compensation model is evaluated at, °C.
pub const MIN_TEMPERATURE_C: f64 = -55.0;
/// Highest temperature the compensation model is evaluated at, °C.
pub const MAX_TEMPERATURE_C: f64 = 125.0;
/// Default reference temperature of `bias` and `scale`, °C (the usual datasheet condition).
pub const DEFAULT_REFERENCE_TEMPERATURE_C: f64 = 25.0;

/// Per-channel calibration. Every list is either empty or has one entry per channel; empty means
/// zero bias, unit scale, no temperature dependence, temperature sensor 0.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChannelCalibration {
    /// Bias at the reference temperature, SI units (rad/s or m/s²).
    pub bias: Vec<f64>,
    /// Scale factor at the reference temperature (dimensionless, > 0).
    pub scale: Vec<f64>,
    /// Bias temperature coefficient, SI units per °C.
    pub bias_per_c: Vec<f64>,
    /// Scale-factor temperature coefficient, ppm per °C.
    pub scale_ppm_per_c: Vec<f64>,
    /// Temperature at which `bias` and `scale` hold, °C.
    pub reference_temperature_c: f64,
    /// Index of the module temperature sensor each channel uses (< 4).
    pub temperature_sensor: Vec<usize>,
}

impl Default for ChannelCalibration {
    fn default() -> Self {
        Self {
            bias: Vec::new(),
            scale: Vec::new(),
            bias_per_c: Vec::new(),
            scale_ppm_per_c: Vec::new(),
            reference_temperature_c: DEFAULT_REFERENCE_TEMPERATURE_C,
            temperature_sensor: Vec::new(),
        }
    }
}

impl ChannelCalibration {
    /// Checks the lists against the channel count `n` (length n or empty) and their ranges:
    /// bias and bias_per_c finite, scale finite and > 0, the reference temperature within
    /// [`MIN_TEMPERATURE_C`]..=[`MAX_TEMPERATURE_C`], the scale factor staying > 0 over that
    /// whole range, temperature sensor indices < 4. Errors name the field and value.
    pub fn validate(&self, n: usize) -> Result<(), ConfigError> {
        check_len("bias", self.bias.len(), n)?;
        check_len("scale", self.scale.len(), n)?;
        check_len("bias_per_c", self.bias_per_c.len(), n)?;
        check_len("scale_ppm_per_c", self.scale_ppm_per_c.len(), n)?;
        check_len("temperature_sensor", self.temperature_sensor.len(), n)?;
        check_all("bias", &self.bias, "must be finite", |b| b.is_finite())?;
        check_all("scale", &self.scale, "must be finite and > 0", |s| {
            s.is_finite() && s > 0.0
        })?;
        check_all("bias_per_c", &self.bias_per_c, "must be finite", |b| {
            b.is_finite()
        })?;
        let t_ref = self.reference_temperature_c;
        if !(MIN_TEMPERATURE_C..=MAX_TEMPERATURE_C).contains(&t_ref) {
            return Err(ConfigError::new(
                "reference_temperature_c",
                t_ref,
                format!("must be in {MIN_TEMPERATURE_C}..={MAX_TEMPERATURE_C} °C"),
            ));
        }
        check_all(
            "scale_ppm_per_c",
            &self.scale_ppm_per_c,
            "must be finite and keep the scale factor > 0 over -55..=125 °C",
            |k| {
                let relative = |t: f64| 1.0 + k * 1e-6 * (t - t_ref);
                k.is_finite()
                    && relative(MIN_TEMPERATURE_C) > 0.0
                    && relative(MAX_TEMPERATURE_C) > 0.0
            },
        )?;
        if let Some((i, s)) = self
            .temperature_sensor
            .iter()
            .enumerate()
            .find(|(_, s)| **s >= MAX_TEMPERATURES)
        {
            return Err(ConfigError::new(
                format!("temperature_sensor[{i}]"),
                s,
                format!("must be < {MAX_TEMPERATURES} (module temperature sensors)"),
            ));
        }
        Ok(())
    }
}

fn check_len(field: &str, len: usize, n: usize) -> Result<(), ConfigError> {
    if len == 0 || len == n {
        Ok(())
    } else {
        Err(ConfigError::new(
            field,
            format!("{len} entries"),
            format!("must have {n} entries (one per channel) or be empty"),
        ))
    }
}

fn check_all(
    field: &str,
    values: &[f64],
    reason: &str,
    ok: impl Fn(f64) -> bool,
) -> Result<(), ConfigError> {
    match values.iter().enumerate().find(|(_, v)| !ok(**v)) {
        Some((i, v)) => Err(ConfigError::new(format!("{field}[{i}]"), v, reason)),
        None => Ok(()),
    }
}

/// Validated calibration of N channels, ready for per-sample use without allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    n: usize,
    lsb: f64,
    bias: [f64; MAX_CHANNELS],
    inv_scale: [f64; MAX_CHANNELS],
    scale: [f64; MAX_CHANNELS],
    bias_per_c: [f64; MAX_CHANNELS],
    /// Absolute scale change per °C: scale · ppm · 1e-6.
    scale_per_c: [f64; MAX_CHANNELS],
    sensor: [usize; MAX_CHANNELS],
    reference_c: f64,
}

impl Calibration {
    /// Builds the calibration of `n` channels whose ADC step is `lsb` SI units per count.
    pub fn new(config: &ChannelCalibration, n: usize, lsb: f64) -> Result<Self, ConfigError> {
        if !(1..=MAX_CHANNELS).contains(&n) {
            return Err(ConfigError::new(
                "n",
                n,
                format!("must be in 1..={MAX_CHANNELS}"),
            ));
        }
        if !(lsb.is_finite() && lsb > 0.0) {
            return Err(ConfigError::new("lsb", lsb, "must be finite and > 0"));
        }
        config.validate(n)?;
        let fill = |src: &[f64], default: f64| {
            let mut dst = [default; MAX_CHANNELS];
            dst.iter_mut().zip(src).for_each(|(d, s)| *d = *s);
            dst
        };
        let scale = fill(&config.scale, 1.0);
        let ppm = fill(&config.scale_ppm_per_c, 0.0);
        let mut sensor = [0; MAX_CHANNELS];
        sensor
            .iter_mut()
            .zip(&config.temperature_sensor)
            .for_each(|(d, s)| *d = *s);
        Ok(Self {
            n,
            lsb,
            bias: fill(&config.bias, 0.0),
            inv_scale: scale.map(|s| 1.0 / s),
            scale,
            bias_per_c: fill(&config.bias_per_c, 0.0),
            scale_per_c: std::array::from_fn(|i| scale[i] * ppm[i] * 1e-6),
            sensor,
            reference_c: config.reference_temperature_c,
        })
    }

    /// Number of channels.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Converts one channel's counts to SI units at the reference temperature; NaN for a channel
    /// index outside 0..N.
    pub fn apply(&self, channel: usize, counts: i16) -> f64 {
        if channel >= self.n {
            return f64::NAN;
        }
        (f64::from(counts) * self.lsb - self.bias[channel]) * self.inv_scale[channel]
    }

    /// Converts the first N entries of `counts` into `out` at the reference temperature; channels
    /// missing from `counts` are NaN.
    pub fn apply_all(&self, counts: &[i16], out: &mut [f64; MAX_CHANNELS]) {
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            *o = counts.get(i).map_or(f64::NAN, |&c| self.apply(i, c));
        }
    }

    /// Converts one channel's counts to SI units at module temperature `temperature_c` (clamped
    /// to the calibrated range; non-finite = reference). NaN for a channel index outside 0..N.
    pub fn apply_with_temperature(&self, channel: usize, counts: i16, temperature_c: f64) -> f64 {
        if channel >= self.n {
            return f64::NAN;
        }
        let dt = self.temperature_offset(temperature_c);
        let bias = self.bias[channel] + self.bias_per_c[channel] * dt;
        let scale = self.scale[channel] + self.scale_per_c[channel] * dt;
        (f64::from(counts) * self.lsb - bias) / scale
    }

    /// Converts the first N entries of `counts` into `out`, each channel compensated with the
    /// module temperature `temperatures_c[temperature_sensor_i]` (°C). A sensor index beyond
    /// `temperatures_c` counts as a missing reading (reference temperature); channels missing
    /// from `counts` are NaN.
    pub fn apply_all_with_temperature(
        &self,
        counts: &[i16],
        temperatures_c: &[f32],
        out: &mut [f64; MAX_CHANNELS],
    ) {
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            let t = temperatures_c
                .get(self.sensor[i])
                .map_or(f64::NAN, |&t| f64::from(t));
            *o = counts
                .get(i)
                .map_or(f64::NAN, |&c| self.apply_with_temperature(i, c, t));
        }
    }

    /// Index of the module temperature sensor channel `channel` uses (0 outside 0..N).
    pub fn temperature_sensor(&self, channel: usize) -> usize {
        if channel < self.n {
            self.sensor[channel]
        } else {
            0
        }
    }

    /// T − T_ref with T clamped to the calibrated range; 0 for a non-finite T.
    fn temperature_offset(&self, temperature_c: f64) -> f64 {
        if temperature_c.is_finite() {
            temperature_c.clamp(MIN_TEMPERATURE_C, MAX_TEMPERATURE_C) - self.reference_c
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn applies_bias_then_scale() {
        let cfg = ChannelCalibration {
            bias: vec![0.1, -0.2, 0.0],
            scale: vec![1.0, 2.0, 0.5],
            ..Default::default()
        };
        let cal = Calibration::new(&cfg, 3, 0.01).unwrap();
        assert!((cal.apply(0, 100) - 0.9).abs() < 1e-12);
        assert!((cal.apply(1, 100) - 0.6).abs() < 1e-12);
        assert!((cal.apply(2, -50) - (-1.0)).abs() < 1e-12);
        assert!(cal.apply(3, 1).is_nan());
    }

    #[test]
    fn empty_lists_mean_identity() {
        let cal = Calibration::new(&ChannelCalibration::default(), 4, 0.5).unwrap();
        let mut out = [0.0; MAX_CHANNELS];
        cal.apply_all(&[2, -4, 6], &mut out);
        assert_eq!(&out[..3], &[1.0, -2.0, 3.0]);
        assert!(out[3].is_nan());
    }

    #[test]
    fn rejects_bad_lists_naming_field_and_value() {
        let wrong_len = ChannelCalibration {
            bias: vec![0.0; 3],
            scale: vec![],
            ..Default::default()
        };
        let e = wrong_len.validate(4).unwrap_err();
        assert_eq!(e.field, "bias");
        assert!(e.to_string().contains("3 entries"), "{e}");
        let zero_scale = ChannelCalibration {
            bias: vec![],
            scale: vec![1.0, 0.0, 1.0, 1.0],
            ..Default::default()
        };
        let e = zero_scale.validate(4).unwrap_err();
        assert_eq!(e.to_string(), "scale[1] = 0: must be finite and > 0");
        let nan_bias = ChannelCalibration {
            bias: vec![0.0, f64::NAN, 0.0, 0.0],
            scale: vec![],
            ..Default::default()
        };
        assert_eq!(nan_bias.validate(4).unwrap_err().field, "bias[1]");
        let e = Calibration::new(&ChannelCalibration::default(), 4, -1.0).unwrap_err();
        assert_eq!(e.to_string(), "lsb = -1: must be finite and > 0");
    }
}
