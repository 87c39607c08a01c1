//! Gravity: the standard value and WGS84 normal gravity at a latitude and height.

use crate::wgs84::{WGS84_A, WGS84_E2, WGS84_F, WGS84_M};

/// Normal gravity at the equator, m/s².
pub const GRAVITY_EQUATOR: f64 = 9.780_325_335_9;
/// Somigliana constant k = (b γ_p − a γ_e) / (a γ_e).
pub const SOMIGLIANA_K: f64 = 1.931_852_652_41e-3;
/// Standard gravity, m/s² (used only where a latitude is not known).
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// WGS84 normal gravity magnitude at geodetic latitude and height above the ellipsoid, m/s².
///
/// Somigliana's closed form on the ellipsoid, `γ(φ) = γ_e (1 + k sin²φ)/√(1 − e² sin²φ)`, with the
/// second-order free-air correction
/// `γ(φ,h) = γ(φ) [1 − (2/a)(1 + f + m − 2f sin²φ) h + 3h²/a²]` (NIMA TR8350.2, chapter 4).
/// It includes the centrifugal part of the Earth's rotation, i.e. it is what a plumb bob feels,
/// which is what a static accelerometer cancels.
pub fn normal_gravity(lat_rad: f64, alt_m: f64) -> f64 {
    let s2 = lat_rad.sin().powi(2);
    let surface = GRAVITY_EQUATOR * (1.0 + SOMIGLIANA_K * s2) / (1.0 - WGS84_E2 * s2).sqrt();
    let height_factor = 1.0
        - 2.0 / WGS84_A * (1.0 + WGS84_F + WGS84_M - 2.0 * WGS84_F * s2) * alt_m
        + 3.0 * alt_m * alt_m / (WGS84_A * WGS84_A);
    surface * height_factor
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_gravity_matches_published_equator_and_pole_values() {
        assert!((normal_gravity(0.0, 0.0) - 9.780_325_335_9).abs() < 1e-10);
        // WGS84 normal gravity at the pole, 9.832 184 937 8 m/s².
        let pole = normal_gravity(std::f64::consts::FRAC_PI_2, 0.0);
        assert!((pole - 9.832_184_937_8).abs() < 1e-8, "{pole}");
    }

    #[test]
    fn free_air_gradient_is_about_3_086e_minus_6_per_metre() {
        let lat = 45f64.to_radians();
        let gradient = (normal_gravity(lat, 0.0) - normal_gravity(lat, 100.0)) / 100.0;
        assert!((gradient - 3.086e-6).abs() < 0.01e-6, "{gradient}");
    }
}
