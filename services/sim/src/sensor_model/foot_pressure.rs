//! Foot-pressure sensor: no walking scenario loads it yet, so it reads 0 plus noise, clamped to the
//! raw 16-bit range.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_acquisition::protocol::AuxFrame;

#[derive(Debug, Clone)]
pub(crate) struct FootPressureModel {
    pub noise_counts: f64,
}

impl FootPressureModel {
    pub fn sample(&self, load_counts: f64, rng: &mut ChaCha8Rng, out: &mut AuxFrame) {
        let v = load_counts + self.noise_counts * rng.sample::<f64, _>(StandardNormal);
        out.foot_pressure = v.round().clamp(0.0, f64::from(u16::MAX)) as u16;
    }
}
