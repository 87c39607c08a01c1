//! The detector settings the evaluation chooses from, and the fuser configuration of each.
//!
//! Five settings are tuned from data, each over a small grid: the false-alarm probability (the
//! parity threshold), the channel noise σ given to the detector (a multiple of the
//! configuration's reference σ, which seeds the adaptive parity noise), the motion noise fraction
//! (scale-factor and misalignment disagreement between units), the timing skew (uncertainty of
//! the sampling instants between units) and the noise-outlier ratio (the channel-health check's
//! threshold). No setting is ever chosen on the flight it is scored on
//! (see [`super::cross_validation`]).

use rins_fusion::config::ImuBlock;
use rins_fusion::{FdiConfig, FusionConfig, NoiseConfig, ParityNoise, PerSensor};
use serde::Serialize;

use super::layout::Layout;
use crate::datasets::quadrotor::IMU_RATE_HZ;

/// Swept false-alarm probabilities per sample, most sensitive first (the ROC's points).
pub const FALSE_ALARM_PROBABILITIES: [f64; 5] = [1e-6, 1e-8, 1e-10, 1e-12, 1e-14];
/// Detector σ as multiples of the reference σ.
pub const NOISE_SCALES: [f64; 3] = [0.7, 1.0, 1.4];
/// Scale-factor and misalignment disagreement between units, fraction of |x|: consumer MEMS
/// units are specified at 1–2 % each, plus the error of the estimated installation.
pub const MOTION_NOISE_FRACTIONS: [f64; 2] = [0.02, 0.05];
/// Uncertainty of the sampling instants between units, s: each unit samples somewhere in its
/// own 8.3 ms period, and the sub-row lag estimate wanders.
pub const TIMING_SKEWS_S: [f64; 2] = [0.004, 0.010];
/// Noise-outlier thresholds: a channel's first-difference variance over the median of its
/// peers' (25: the product's default; the separate units of the recordings vibrate unlike each
/// other far more than the channels of one block).
pub const NOISE_RATIOS: [f64; 2] = [25.0, 60.0];
/// Learning phase of the parity offset and adaptive noise, s (declarations suspended).
pub const LEARNING_S: f64 = 2.0;
/// Averaging length of the adaptive parity noise, s.
pub const ADAPTIVE_WINDOW_S: f64 = 10.0;

/// One detector setting.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DetectorSetting {
    /// Probability that a fault-free sample raises a persistent parity alarm.
    pub false_alarm_probability: f64,
    /// Detector σ over the configuration's reference σ.
    pub noise_scale: f64,
    /// Channel error proportional to the measured quantity, fraction.
    pub motion_noise_fraction: f64,
    /// Sampling-instant uncertainty between units, s.
    pub timing_skew_s: f64,
    /// Noise-outlier threshold (variance ratio).
    pub noise_ratio: f64,
}

/// Every setting of the grid, grouped by false-alarm probability in the order of
/// [`FALSE_ALARM_PROBABILITIES`].
pub fn grid() -> Vec<DetectorSetting> {
    let mut v = Vec::new();
    for false_alarm_probability in FALSE_ALARM_PROBABILITIES {
        for noise_scale in NOISE_SCALES {
            for motion_noise_fraction in MOTION_NOISE_FRACTIONS {
                for timing_skew_s in TIMING_SKEWS_S {
                    for noise_ratio in NOISE_RATIOS {
                        v.push(DetectorSetting {
                            false_alarm_probability,
                            noise_scale,
                            motion_noise_fraction,
                            timing_skew_s,
                            noise_ratio,
                        });
                    }
                }
            }
        }
    }
    v
}

/// The evaluation's fusion settings for one layout and detector setting: the configured
/// `[fusion.fdi]` with the setting applied, adaptive parity noise and the learning and adaptive
/// windows at the data's rate; the layout's geometry; identity calibration (the data are
/// calibrated already); the default weighted least squares.
pub(crate) fn fusion_config(
    base: &FdiConfig,
    layout: Layout,
    setting: &DetectorSetting,
) -> FusionConfig {
    let noise = layout.noise();
    let mut fdi = base.clone();
    fdi.false_alarm_probability = setting.false_alarm_probability;
    fdi.parity_noise = ParityNoise::Adaptive;
    fdi.learning_samples = (LEARNING_S * IMU_RATE_HZ) as u32;
    fdi.adaptive_window = (ADAPTIVE_WINDOW_S * IMU_RATE_HZ) as u32;
    fdi.motion_noise_fraction = setting.motion_noise_fraction;
    fdi.timing_skew_s = setting.timing_skew_s;
    fdi.noise_ratio = setting.noise_ratio;
    FusionConfig {
        geometry: PerSensor {
            gyro: layout.geometry(),
            accel: layout.geometry(),
        },
        noise: NoiseConfig::from_per_sample_sigma(
            noise.gyro_sigma_rps * setting.noise_scale,
            noise.accel_sigma_mps2 * setting.noise_scale,
            IMU_RATE_HZ,
        ),
        calibration: PerSensor::default(),
        fdi,
        // The flights start in motion: no estimate of channel biases at rest (the relative
        // biases are removed in the pre-processing instead).
        rest_bias_s: 0.0,
        block: ImuBlock {
            imu_rate_hz: IMU_RATE_HZ,
            ..ImuBlock::default()
        },
        ..FusionConfig::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_holds_every_combination_once_grouped_by_probability() {
        let g = grid();
        assert_eq!(g.len(), 5 * 3 * 2 * 2 * 2);
        let per = g.len() / FALSE_ALARM_PROBABILITIES.len();
        for (i, p) in FALSE_ALARM_PROBABILITIES.iter().enumerate() {
            assert!(
                g[i * per..(i + 1) * per]
                    .iter()
                    .all(|s| s.false_alarm_probability == *p)
            );
        }
        for (i, a) in g.iter().enumerate() {
            assert!(g[i + 1..].iter().all(|b| a != b));
        }
    }

    #[test]
    fn every_setting_gives_a_valid_fuser_configuration() {
        for layout in [Layout::Pyramid4, Layout::Stacked { units: 3 }] {
            for s in grid() {
                let f = fusion_config(&FdiConfig::default(), layout, &s);
                f.validate().expect("valid");
                assert_eq!(f.fdi.false_alarm_probability, s.false_alarm_probability);
            }
        }
    }
}
