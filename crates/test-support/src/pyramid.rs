//! Sensitive axes of the skewed pyramid layouts the tests use, built independently of the
//! product's geometry code so that they can also check it.
//!
//! Axis i of an n-axis pyramid lies on a cone of elevation α at azimuth β_i = β0 + i·360°/n:
//! `h_i = [cos α cos β_i, cos α sin β_i, sin α]`.

/// Elevation of the sensor block's four-axis pyramid, degrees.
pub const BLOCK_ALPHA_DEG: f64 = 28.7;

/// Azimuth of the first axis of the sensor block's pyramid, degrees.
pub const BLOCK_BETA0_DEG: f64 = 45.0;

/// Elevation at which an evenly spaced pyramid has HᵀH ∝ I (tan²α = 1/2), degrees.
pub const OPTIMAL_ALPHA_DEG: f64 = 35.264_389_682_754_654;

/// The `n` unit axes of a pyramid of elevation `alpha_deg` whose first axis has azimuth
/// `beta0_deg`.
pub fn pyramid_axes(n: usize, alpha_deg: f64, beta0_deg: f64) -> Vec<[f64; 3]> {
    let (sa, ca) = alpha_deg.to_radians().sin_cos();
    (0..n)
        .map(|i| {
            let (sb, cb) = (beta0_deg + i as f64 * 360.0 / n as f64)
                .to_radians()
                .sin_cos();
            [ca * cb, ca * sb, sa]
        })
        .collect()
}

/// The sensor block's four axes: α = 28.7°, β0 = 45°.
pub fn block_pyramid_axes() -> Vec<[f64; 3]> {
    pyramid_axes(4, BLOCK_ALPHA_DEG, BLOCK_BETA0_DEG)
}

/// Four axes at the optimal elevation (HᵀH = 4/3 I), β0 = 45°.
pub fn optimal_pyramid_axes() -> Vec<[f64; 3]> {
    pyramid_axes(4, OPTIMAL_ALPHA_DEG, BLOCK_BETA0_DEG)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_optimal_pyramid_is_isotropic() {
        let axes = optimal_pyramid_axes();
        for r in 0..3 {
            for c in 0..3 {
                let hth: f64 = axes.iter().map(|h| h[r] * h[c]).sum();
                let expected = if r == c { 4.0 / 3.0 } else { 0.0 };
                assert!((hth - expected).abs() < 1e-12, "({r}, {c}): {hth}");
            }
        }
    }

    #[test]
    fn axes_are_unit_vectors_on_the_cone() {
        for h in pyramid_axes(6, 20.0, 10.0) {
            let norm = (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
            assert!((norm - 1.0).abs() < 1e-15);
            assert!((h[2] - 20f64.to_radians().sin()).abs() < 1e-15);
        }
        let first = block_pyramid_axes()[0];
        let c = 28.7f64.to_radians().cos() * 45f64.to_radians().cos();
        assert!((first[0] - c).abs() < 1e-15 && (first[1] - c).abs() < 1e-15);
    }
}
