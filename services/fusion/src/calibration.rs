//! ADC counts to SI units per channel: `value = (counts·lsb − bias_i) / scale_i`.

use crate::error::ConfigError;
use crate::geometry::MAX_CHANNELS;
use serde::Deserialize;

/// Per-channel bias (SI units: rad/s or m/s²) and scale factor (dimensionless).
/// Empty lists mean zero bias and unit scale; otherwise each list has one entry per channel.
#[derive(Debug, Clone, PartialEq, Default, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ChannelCalibration {
    pub bias: Vec<f64>,
    pub scale: Vec<f64>,
}

impl ChannelCalibration {
    /// Checks the lists against the channel count `n`: length n or empty, bias finite, scale
    /// finite and > 0.
    pub fn validate(&self, n: usize) -> Result<(), ConfigError> {
        check_len("bias", &self.bias, n)?;
        check_len("scale", &self.scale, n)?;
        for (i, b) in self.bias.iter().enumerate() {
            if !b.is_finite() {
                return Err(ConfigError::new(format!("bias[{i}]"), b, "must be finite"));
            }
        }
        for (i, s) in self.scale.iter().enumerate() {
            if !(s.is_finite() && *s > 0.0) {
                return Err(ConfigError::new(
                    format!("scale[{i}]"),
                    s,
                    "must be finite and > 0",
                ));
            }
        }
        Ok(())
    }
}

fn check_len(field: &str, v: &[f64], n: usize) -> Result<(), ConfigError> {
    if v.is_empty() || v.len() == n {
        Ok(())
    } else {
        Err(ConfigError::new(
            field,
            format!("{} entries", v.len()),
            format!("must have {n} entries (one per channel) or be empty"),
        ))
    }
}

/// Validated calibration of N channels, ready for per-sample use without allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calibration {
    n: usize,
    lsb: f64,
    bias: [f64; MAX_CHANNELS],
    inv_scale: [f64; MAX_CHANNELS],
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
        let mut bias = [0.0; MAX_CHANNELS];
        let mut inv_scale = [1.0; MAX_CHANNELS];
        for (dst, src) in bias.iter_mut().zip(&config.bias) {
            *dst = *src;
        }
        for (dst, src) in inv_scale.iter_mut().zip(&config.scale) {
            *dst = 1.0 / *src;
        }
        Ok(Self {
            n,
            lsb,
            bias,
            inv_scale,
        })
    }

    /// Number of channels.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Converts one channel's counts to SI units; NaN for a channel index outside 0..N.
    pub fn apply(&self, channel: usize, counts: i16) -> f64 {
        if channel >= self.n {
            return f64::NAN;
        }
        (f64::from(counts) * self.lsb - self.bias[channel]) * self.inv_scale[channel]
    }

    /// Converts the first N entries of `counts` into `out`; channels missing from `counts` are NaN.
    pub fn apply_all(&self, counts: &[i16], out: &mut [f64; MAX_CHANNELS]) {
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            *o = counts.get(i).map_or(f64::NAN, |&c| self.apply(i, c));
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
        };
        let e = wrong_len.validate(4).unwrap_err();
        assert_eq!(e.field, "bias");
        assert!(e.to_string().contains("3 entries"), "{e}");
        let zero_scale = ChannelCalibration {
            bias: vec![],
            scale: vec![1.0, 0.0, 1.0, 1.0],
        };
        let e = zero_scale.validate(4).unwrap_err();
        assert_eq!(e.to_string(), "scale[1] = 0: must be finite and > 0");
        let nan_bias = ChannelCalibration {
            bias: vec![0.0, f64::NAN, 0.0, 0.0],
            scale: vec![],
        };
        assert_eq!(nan_bias.validate(4).unwrap_err().field, "bias[1]");
        let e = Calibration::new(&ChannelCalibration::default(), 4, -1.0).unwrap_err();
        assert_eq!(e.to_string(), "lsb = -1: must be finite and > 0");
    }
}
