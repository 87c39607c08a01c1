//! WGS84 Earth model: radii of curvature and normal gravity.
//!
//! The navigator treats the Earth as non-rotating (no Earth rate, Coriolis or transport rate), but keeps
//! the ellipsoid so that latitude/longitude increments and gravity are right to first order for a small
//! vehicle over short flights.

/// WGS84 semi-major axis, m.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS84 first eccentricity squared.
pub const WGS84_E2: f64 = 6.694_379_990_14e-3;
/// Normal gravity at the equator, m/s².
pub const GRAVITY_EQUATOR: f64 = 9.780_325_335_9;
/// Somigliana constant k = (b γ_p − a γ_e) / (a γ_e).
pub const SOMIGLIANA_K: f64 = 1.931_852_652_41e-3;
/// m = ω² a² b / GM, the ratio of centrifugal to gravitational acceleration at the equator.
pub const WGS84_M: f64 = 3.449_786_003_08e-3;
/// Standard gravity, m/s² (used only where a latitude is not known).
pub const STANDARD_GRAVITY: f64 = 9.806_65;

/// Meridian (north–south) radius of curvature `R_N = a(1−e²)/(1−e² sin²φ)^{3/2}`, m.
///
/// This is the radius that turns north velocity into latitude rate: `φ̇ = v_N / (R_N + h)`.
pub fn meridian_radius(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    let w = 1.0 - WGS84_E2 * s * s;
    WGS84_A * (1.0 - WGS84_E2) / (w * w.sqrt())
}

/// Prime-vertical (east–west) radius of curvature `R_E = a/√(1−e² sin²φ)`, m.
///
/// This is the radius that turns east velocity into longitude rate: `λ̇ = v_E / ((R_E + h) cos φ)`.
pub fn prime_vertical_radius(lat_rad: f64) -> f64 {
    let s = lat_rad.sin();
    WGS84_A / (1.0 - WGS84_E2 * s * s).sqrt()
}

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

    #[test]
    fn radii_at_equator_and_pole() {
        let b2_over_a = WGS84_A * (1.0 - WGS84_E2);
        assert!((meridian_radius(0.0) - b2_over_a).abs() < 1e-6);
        assert!((prime_vertical_radius(0.0) - WGS84_A).abs() < 1e-6);
        let pole = std::f64::consts::FRAC_PI_2;
        // At the pole both radii equal a²/b = a/√(1−e²).
        let polar = WGS84_A / (1.0 - WGS84_E2).sqrt();
        assert!((meridian_radius(pole) - polar).abs() < 1e-6);
        assert!((prime_vertical_radius(pole) - polar).abs() < 1e-6);
    }
}
