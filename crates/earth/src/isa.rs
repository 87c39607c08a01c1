//! ISA troposphere: `h = (T0/L)·(1 − (p/p0)^(R·L/(g·M)))` with p0 = QNH (U.S. Standard Atmosphere
//! 1976, the model barometric altimeters are built to); the altimeter turns pressure into height
//! with it, the simulator height into pressure.
//!
//! Valid below the tropopause (11 km); heights are above the QNH reference (mean sea level when
//! QNH is the local sea-level pressure).

/// Sea-level standard temperature, K.
pub const T0_K: f64 = 288.15;
/// Temperature lapse rate, K/m.
pub const LAPSE_K_PER_M: f64 = 0.0065;
/// Standard gravity, m/s².
pub const G0_MPS2: f64 = crate::gravity::STANDARD_GRAVITY;
/// Molar mass of dry air, kg/mol.
pub const MOLAR_MASS_KG_PER_MOL: f64 = 0.0289644;
/// Universal gas constant as defined by the U.S. Standard Atmosphere 1976, J/(mol·K): with it the
/// pressure law reproduces the standard-atmosphere tables that barometric altimeters are built to.
pub const GAS_CONSTANT: f64 = 8.31432;
/// Standard sea-level pressure, Pa.
pub const P0_STANDARD_PA: f64 = 101_325.0;

/// Exponent R·L/(g·M) ≈ 0.190263.
pub const EXPONENT: f64 = GAS_CONSTANT * LAPSE_K_PER_M / (G0_MPS2 * MOLAR_MASS_KG_PER_MOL);

/// Height scale T0/L ≈ 44 330.8 m: the altitude at which the ISA pressure would reach zero.
pub const HEIGHT_SCALE_M: f64 = T0_K / LAPSE_K_PER_M;

/// Altitude in metres above the QNH reference for static pressure `p_pa`. Both pressures must be
/// positive; the result is NaN otherwise.
pub fn pressure_to_altitude(p_pa: f64, qnh_pa: f64) -> f64 {
    if !(p_pa > 0.0 && qnh_pa > 0.0) {
        return f64::NAN;
    }
    HEIGHT_SCALE_M * (1.0 - (p_pa / qnh_pa).powf(EXPONENT))
}

/// Static pressure in Pa at altitude `h_m` above the QNH reference; 0 at or above T0/L.
pub fn altitude_to_pressure(h_m: f64, qnh_pa: f64) -> f64 {
    qnh_pa * (1.0 - h_m / HEIGHT_SCALE_M).max(0.0).powf(1.0 / EXPONENT)
}

/// ISA temperature at altitude `h_m`, K.
pub fn temperature_k(h_m: f64) -> f64 {
    T0_K - LAPSE_K_PER_M * h_m
}

/// Dry-air density at altitude `h_m` above the QNH reference, kg/m³ (`ρ = p·M / (R·T)`, 1.225 at
/// standard sea level): what turns a pitot's dynamic pressure ½ρV² into airspeed.
pub fn density_kg_m3(h_m: f64, qnh_pa: f64) -> f64 {
    altitude_to_pressure(h_m, qnh_pa) * MOLAR_MASS_KG_PER_MOL / (GAS_CONSTANT * temperature_k(h_m))
}

/// dh/dp at `p_pa` in m/Pa (negative: height falls as pressure rises). Converts a pressure noise
/// σ_p into a height noise |dh/dp|·σ_p.
pub fn altitude_per_pascal(p_pa: f64, qnh_pa: f64) -> f64 {
    if !(p_pa > 0.0 && qnh_pa > 0.0) {
        return f64::NAN;
    }
    -HEIGHT_SCALE_M * EXPONENT * (p_pa / qnh_pa).powf(EXPONENT) / p_pa
}
