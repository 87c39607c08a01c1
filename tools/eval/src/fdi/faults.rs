//! The faults injected into one channel of a prepared flight, and how each changes a count.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_fusion::fdi::channel_health::{COUNT_MAX, COUNT_MIN};

/// Bias step sizes injected, in units of the configuration's reference σ.
pub const BIAS_STEPS_SIGMA: [f64; 3] = [5.0, 10.0, 20.0];
/// Slope of the injected ramp, reference σ per second (20 σ after 10 s).
pub const RAMP_SIGMA_PER_S: f64 = 2.0;
/// σ of the white noise added by the noise-increase fault, in reference σ: the channel then
/// carries about √(1 + 3²) ≈ 3.2 times the noise of its peers.
pub const NOISE_INCREASE_SIGMA: f64 = 3.0;

/// One fault kind, sized in the configuration's reference σ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FaultKind {
    /// The channel's valid bit cleared.
    Dead,
    /// The count frozen at its last fault-free value.
    Stuck,
    /// A step of this many σ.
    Bias(f64),
    /// A ramp of this many σ per second from zero at the fault.
    Ramp(f64),
    /// White noise of this many σ added.
    Noise(f64),
    /// The count at the upper rail.
    Saturated,
}

impl FaultKind {
    /// Every kind injected, in report order.
    pub(crate) fn all() -> Vec<FaultKind> {
        let mut v = vec![FaultKind::Dead, FaultKind::Stuck];
        v.extend(BIAS_STEPS_SIGMA.map(FaultKind::Bias));
        v.push(FaultKind::Ramp(RAMP_SIGMA_PER_S));
        v.push(FaultKind::Noise(NOISE_INCREASE_SIGMA));
        v.push(FaultKind::Saturated);
        v
    }

    pub(crate) fn name(self) -> String {
        match self {
            FaultKind::Dead => "dead".into(),
            FaultKind::Stuck => "stuck".into(),
            FaultKind::Bias(s) => format!("bias {s}σ"),
            FaultKind::Ramp(s) => format!("ramp {s}σ/s"),
            FaultKind::Noise(s) => format!("noise +{s}σ"),
            FaultKind::Saturated => "saturated".into(),
        }
    }

    /// The largest bias step among `faults` (−∞ when there is none): the step the detection
    /// target is set on.
    pub(crate) fn largest_bias(faults: &[FaultKind]) -> f64 {
        faults
            .iter()
            .filter_map(|k| match k {
                FaultKind::Bias(s) => Some(*s),
                _ => None,
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Channel-health faults: the product's checks on the counts find them whatever the motion.
    pub(crate) fn is_health(self) -> bool {
        matches!(
            self,
            FaultKind::Dead | FaultKind::Stuck | FaultKind::Saturated
        )
    }
}

/// One fault applied to one channel's counts, sample by sample from the fault row on.
pub(crate) struct Injector {
    kind: FaultKind,
    /// Reference σ in counts.
    sigma_counts: f64,
    rate_hz: f64,
    frozen: i16,
    noise: ChaCha8Rng,
}

impl Injector {
    /// `frozen` is the channel's last fault-free count; `seed` makes the noise fault repeatable.
    pub(crate) fn new(
        kind: FaultKind,
        sigma_counts: f64,
        rate_hz: f64,
        frozen: i16,
        seed: u64,
    ) -> Self {
        Self {
            kind,
            sigma_counts,
            rate_hz,
            frozen,
            noise: ChaCha8Rng::seed_from_u64(seed),
        }
    }

    /// Whether the channel still delivers a sample (a dead one does not).
    pub(crate) fn valid(&self) -> bool {
        self.kind != FaultKind::Dead
    }

    /// The faulty count of the `k`-th faulty sample (k = 0 at the fault row) whose true count is
    /// `count`, clamped to the converter's range.
    pub(crate) fn apply(&mut self, k: usize, count: i16) -> i16 {
        let c = f64::from(count);
        let faulty = match self.kind {
            FaultKind::Dead => c,
            FaultKind::Stuck => f64::from(self.frozen),
            FaultKind::Bias(s) => c + s * self.sigma_counts,
            FaultKind::Ramp(s) => c + s * self.sigma_counts * (k + 1) as f64 / self.rate_hz,
            FaultKind::Noise(s) => {
                let z: f64 = self.noise.sample(StandardNormal);
                c + s * self.sigma_counts * z
            }
            FaultKind::Saturated => f64::from(COUNT_MAX),
        };
        faulty
            .round()
            .clamp(f64::from(COUNT_MIN), f64::from(COUNT_MAX)) as i16
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_fault_changes_the_count_as_its_size_says() {
        let sigma = 10.0;
        let mut bias = Injector::new(FaultKind::Bias(5.0), sigma, 100.0, 0, 1);
        assert_eq!(bias.apply(0, 7), 57);
        let mut ramp = Injector::new(FaultKind::Ramp(2.0), sigma, 100.0, 0, 1);
        // 2σ/s = 20 counts/s: 0.2 counts per sample at 100 Hz, 20 counts after 100 samples.
        assert_eq!(ramp.apply(99, 0), 20);
        let mut stuck = Injector::new(FaultKind::Stuck, sigma, 100.0, -3, 1);
        assert_eq!(stuck.apply(5, 400), -3);
        let mut sat = Injector::new(FaultKind::Saturated, sigma, 100.0, 0, 1);
        assert_eq!(sat.apply(0, 0), COUNT_MAX);
        assert!(!Injector::new(FaultKind::Dead, sigma, 100.0, 0, 1).valid());
        // A bias beyond the rail is clamped to it.
        let mut big = Injector::new(FaultKind::Bias(1e6), sigma, 100.0, 0, 1);
        assert_eq!(big.apply(0, 0), COUNT_MAX);
    }

    #[test]
    fn the_noise_increase_has_the_configured_spread() {
        let mut noise = Injector::new(FaultKind::Noise(3.0), 10.0, 100.0, 0, 7);
        let n = 20_000;
        let xs: Vec<f64> = (0..n).map(|k| f64::from(noise.apply(k, 0))).collect();
        let mean = xs.iter().sum::<f64>() / n as f64;
        let var = xs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n as f64;
        // σ = 30 counts (plus 1/12 count² of rounding); the sample σ is within 2 % of it.
        assert!((var.sqrt() - 30.0).abs() < 0.6, "{}", var.sqrt());
        assert!(mean.abs() < 1.0, "{mean}");
    }
}
