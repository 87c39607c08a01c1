//! Barometer: International Standard Atmosphere (troposphere) at the true altitude plus white noise.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_protocol::BaroFrame;

use super::temperature::to_centi_c;

// One ISA for the whole product: the simulated barometer follows the same law the altimeter inverts.
pub use rins_earth::isa::{
    altitude_to_pressure as isa_pressure_pa, pressure_to_altitude as isa_altitude_m,
    temperature_k as isa_temperature_k,
};

#[derive(Debug, Clone)]
pub(crate) struct BaroModel {
    pub qnh_pa: f64,
    pub noise_pa: f64,
}

impl BaroModel {
    pub fn sample(&self, altitude_m: f64, rng: &mut ChaCha8Rng, out: &mut BaroFrame) {
        let noise = self.noise_pa * rng.sample::<f64, _>(StandardNormal);
        out.pressure_pa = (isa_pressure_pa(altitude_m, self.qnh_pa) + noise) as f32;
        out.temperature_centi_c = to_centi_c(isa_temperature_k(altitude_m) - 273.15);
    }
}
