//! Barometer: International Standard Atmosphere (troposphere) at the true altitude plus white noise.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use rins_acquisition::protocol::BaroFrame;

use super::temperature::to_centi_c;
use crate::GRAVITY_MPS2;

/// ISA sea-level temperature, K.
pub const ISA_T0_K: f64 = 288.15;
/// ISA tropospheric lapse rate, K/m.
pub const ISA_LAPSE_K_PER_M: f64 = 0.0065;
/// Universal gas constant as defined by the U.S. Standard Atmosphere 1976, J/(mol·K); with it the
/// pressure law reproduces the standard-atmosphere tables (exponent 5.255877).
pub const GAS_CONSTANT: f64 = 8.314_32;
/// Molar mass of dry air, kg/mol.
pub const AIR_MOLAR_MASS: f64 = 0.028_964_4;
/// Standard sea-level pressure, Pa.
pub const ISA_P0_PA: f64 = 101_325.0;

/// Exponent g·M/(R·L) of the ISA pressure law (≈ 5.255877).
pub fn isa_exponent() -> f64 {
    GRAVITY_MPS2 * AIR_MOLAR_MASS / (GAS_CONSTANT * ISA_LAPSE_K_PER_M)
}

/// Static pressure at `altitude_m` for sea-level pressure `qnh_pa`: `p = p0 (1 − L h/T0)^(gM/(RL))`.
pub fn isa_pressure_pa(altitude_m: f64, qnh_pa: f64) -> f64 {
    qnh_pa * (1.0 - ISA_LAPSE_K_PER_M * altitude_m / ISA_T0_K).powf(isa_exponent())
}

/// Altitude for a static pressure (inverse of [`isa_pressure_pa`]): `h = (T0/L)(1 − (p/p0)^(RL/(gM)))`.
pub fn isa_altitude_m(pressure_pa: f64, qnh_pa: f64) -> f64 {
    ISA_T0_K / ISA_LAPSE_K_PER_M * (1.0 - (pressure_pa / qnh_pa).powf(1.0 / isa_exponent()))
}

/// ISA temperature at `altitude_m`, K.
pub fn isa_temperature_k(altitude_m: f64) -> f64 {
    ISA_T0_K - ISA_LAPSE_K_PER_M * altitude_m
}

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
