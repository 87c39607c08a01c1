//! The WGS84 ellipsoid: its constants and radii of curvature.
//!
//! rins treats the Earth as non-rotating (no Earth rate, Coriolis or transport rate), but keeps the
//! ellipsoid so that latitude/longitude increments are right for a small vehicle over short flights:
//! the simulator integrates its truth with these radii and the navigator its solution.

/// WGS84 semi-major axis, m.
pub const WGS84_A: f64 = 6_378_137.0;
/// WGS84 flattening.
pub const WGS84_F: f64 = 1.0 / 298.257_223_563;
/// WGS84 first eccentricity squared.
pub const WGS84_E2: f64 = 6.694_379_990_14e-3;
/// m = ω² a² b / GM, the ratio of centrifugal to gravitational acceleration at the equator.
pub const WGS84_M: f64 = 3.449_786_003_08e-3;
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

#[cfg(test)]
mod tests {
    use super::*;

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
