//! Estimate against truth: attitude and position errors, and the filter's 3σ bounds from its
//! covariance diagonal.

/// Indices of [`ipc_types::NavState::covariance_diag`]: attitude error (3), velocity (3),
/// position NED (3), then the biases.
const ATTITUDE: usize = 0;
const POSITION: usize = 6;

fn normalised(q: [f64; 4]) -> [f64; 4] {
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    q.map(|c| c / n)
}

/// Hamilton product `a ⊗ b`, scalar first.
fn multiply(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    [
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    ]
}

/// The attitude error of `estimate` against `truth` (both body → NED, scalar first), degrees:
/// the rotation vector of `estimate ⊗ truth⁻¹`, the small rotation of the NED frame that takes
/// the true attitude to the estimate, about north, east and down (the axes of the filter's
/// attitude-error states). NaN for a zero or non-finite quaternion.
pub fn attitude_error_deg(estimate: [f64; 4], truth: [f64; 4]) -> [f64; 3] {
    let t = normalised(truth);
    let mut d = multiply(normalised(estimate), [t[0], -t[1], -t[2], -t[3]]);
    // q and −q are the same rotation: take the one of angle ≤ 180°.
    if d[0] < 0.0 {
        d = d.map(|c| -c);
    }
    let s = (d[1] * d[1] + d[2] * d[2] + d[3] * d[3]).sqrt();
    let scale = if s < 1e-12 {
        2.0
    } else {
        2.0 * s.atan2(d[0]) / s
    };
    [d[1], d[2], d[3]].map(|c| (c * scale).to_degrees())
}

/// Three standard deviations of a variance; NaN for a negative or non-finite variance.
pub fn three_sigma(variance: f64) -> f64 {
    if variance.is_finite() && variance >= 0.0 {
        3.0 * variance.sqrt()
    } else {
        f64::NAN
    }
}

/// The 3σ bound of each attitude-error axis (north, east, down), degrees.
pub fn attitude_three_sigma_deg(covariance_diag: &[f64; ipc_types::NAV_STATES]) -> [f64; 3] {
    [0, 1, 2].map(|i| three_sigma(covariance_diag[ATTITUDE + i]).to_degrees())
}

/// The 3σ bounds of the horizontal error (from the north and east variances together) and of the
/// vertical error, metres.
pub fn position_three_sigma_m(covariance_diag: &[f64; ipc_types::NAV_STATES]) -> [f64; 2] {
    let c = &covariance_diag[POSITION..POSITION + 3];
    [three_sigma(c[0] + c[1]), three_sigma(c[2])]
}

/// Horizontal (distance in the north–east plane, ≥ 0) and vertical (estimate minus truth, down
/// positive) error between two local NED positions, metres.
pub fn position_error_m(estimate_ned: [f64; 3], truth_ned: [f64; 3]) -> [f64; 2] {
    let dn = estimate_ned[0] - truth_ned[0];
    let de = estimate_ned[1] - truth_ned[1];
    [dn.hypot(de), estimate_ned[2] - truth_ned[2]]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn about(axis: [f64; 3], angle_deg: f64) -> [f64; 4] {
        let (s, c) = (angle_deg.to_radians() / 2.0).sin_cos();
        [c, axis[0] * s, axis[1] * s, axis[2] * s]
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
    }

    #[test]
    fn a_known_rotation_is_the_error() {
        let truth = about([0.0, 0.0, 1.0], 0.0);
        assert!(close(
            attitude_error_deg(about([0.0, 0.0, 1.0], 10.0), truth),
            [0.0, 0.0, 10.0]
        ));
        // An estimate rotated 2° about north from an arbitrary true attitude.
        let truth = multiply(about([0.0, 0.0, 1.0], 130.0), about([0.0, 1.0, 0.0], 20.0));
        let estimate = multiply(about([1.0, 0.0, 0.0], 2.0), truth);
        assert!(close(attitude_error_deg(estimate, truth), [2.0, 0.0, 0.0]));
        // Same rotation with the sign of the quaternion flipped.
        let flipped = estimate.map(|c| -c);
        assert!(close(attitude_error_deg(flipped, truth), [2.0, 0.0, 0.0]));
        assert!(close(attitude_error_deg(truth, truth), [0.0; 3]));
        assert!(attitude_error_deg([0.0; 4], truth)[0].is_nan());
    }

    #[test]
    fn three_sigma_of_known_variances() {
        assert_eq!(three_sigma(4.0), 6.0);
        assert!(three_sigma(-1.0).is_nan());
        let mut p = [0.0; ipc_types::NAV_STATES];
        p[0] = 0.01f64.to_radians().powi(2);
        p[6] = 9.0;
        p[7] = 16.0;
        p[8] = 1.0;
        let a = attitude_three_sigma_deg(&p);
        assert!((a[0] - 0.03).abs() < 1e-12, "{a:?}");
        assert_eq!(position_three_sigma_m(&p), [15.0, 3.0]);
    }

    #[test]
    fn position_errors_split_horizontal_and_vertical() {
        assert_eq!(
            position_error_m([3.0, 4.0, -2.0], [0.0, 0.0, 0.0]),
            [5.0, -2.0]
        );
    }
}
