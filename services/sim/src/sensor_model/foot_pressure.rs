//! Foot-pressure sensor (FSR under the sole): the true load fraction scaled to the raw 16-bit range
//! (0 = no load, 65535 = full scale, as the acquisition expects), plus white noise, rounded and
//! clamped to the range.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_protocol::AuxFrame;

/// Counts of a fully loaded sensor.
const FULL_SCALE_COUNTS: f64 = u16::MAX as f64;

#[derive(Debug, Clone)]
pub(crate) struct FootPressureModel {
    pub noise_counts: f64,
}

impl FootPressureModel {
    /// Fills `out` for a true load `foot_load` (fraction of full scale, clamped to 0..=1).
    pub fn sample(&self, foot_load: f64, rng: &mut ChaCha8Rng, out: &mut AuxFrame) {
        let load_counts = foot_load.clamp(0.0, 1.0) * FULL_SCALE_COUNTS;
        let v = load_counts + self.noise_counts * rng.sample::<f64, _>(StandardNormal);
        out.foot_pressure = v.round().clamp(0.0, FULL_SCALE_COUNTS) as u16;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    fn read(model: &FootPressureModel, load: f64, rng: &mut ChaCha8Rng) -> u16 {
        let mut out = AuxFrame::default();
        model.sample(load, rng, &mut out);
        out.foot_pressure
    }

    #[test]
    fn noiseless_reading_is_the_load_in_counts() {
        let model = FootPressureModel { noise_counts: 0.0 };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        assert_eq!(read(&model, 0.0, &mut rng), 0);
        assert_eq!(read(&model, 0.8, &mut rng), 52_428); // 0.8 · 65535 = 52428.0
        assert_eq!(read(&model, 1.0, &mut rng), u16::MAX);
        assert_eq!(read(&model, 1.5, &mut rng), u16::MAX);
        assert_eq!(read(&model, -0.2, &mut rng), 0);
    }

    /// With σ = 100 counts the mean of 10 000 readings is within 5σ/√n = 5 counts of the load, and
    /// an unloaded sensor never reads below 0 (the negative half is clamped, so its mean is
    /// σ/√(2π) ≈ 40 counts).
    #[test]
    fn noise_is_centred_on_the_load_and_clamped_at_zero() {
        let model = FootPressureModel {
            noise_counts: 100.0,
        };
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let n = 10_000;
        let loaded: f64 = (0..n)
            .map(|_| f64::from(read(&model, 0.5, &mut rng)))
            .sum::<f64>()
            / f64::from(n);
        assert!((loaded - 0.5 * FULL_SCALE_COUNTS).abs() < 5.0, "{loaded}");
        let unloaded: f64 = (0..n)
            .map(|_| f64::from(read(&model, 0.0, &mut rng)))
            .sum::<f64>()
            / f64::from(n);
        assert!((unloaded - 100.0 / (2.0 * std::f64::consts::PI).sqrt()).abs() < 5.0);
    }
}
