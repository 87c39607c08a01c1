//! Closed-form checks of the error-state EKF.

use nalgebra::{UnitQuaternion, Vector3};
use rins_navigator::ekf::{AidingSource, EkfNoise, ErrorStateEkf, POS, VEL, heading_jacobian};
use rins_navigator::mechanisation::{ImuBias, NominalState, StrapdownConfig};

const LAT: f64 = 0.8;
const G: f64 = 9.806;

/// Noise with negligible attitude and bias uncertainty, so velocity errors are pure accelerometer
/// noise and the closed forms hold.
fn quiet_noise() -> EkfNoise {
    EkfNoise {
        initial_tilt_sigma: 1e-9,
        initial_heading_sigma: 1e-9,
        initial_gyro_bias_sigma: 1e-12,
        initial_accel_bias_sigma: 1e-12,
        gyro_noise_density: 1e-12,
        gyro_bias_walk: 1e-15,
        accel_bias_walk: 1e-15,
        ..EkfNoise::default()
    }
}

fn at_rest(noise: EkfNoise) -> ErrorStateEkf {
    ErrorStateEkf::new(
        NominalState::at_rest(LAT, 0.1, 100.0),
        ImuBias::default(),
        StrapdownConfig::default(),
        noise,
    )
}

/// Specific force at rest for a level body: the reaction to the filter's own gravity.
fn rest_force(ekf: &ErrorStateEkf) -> [f64; 3] {
    [0.0, 0.0, -ekf.strapdown().gravity()]
}

#[test]
fn unaided_velocity_variance_grows_as_the_accelerometer_random_walk() {
    let noise = quiet_noise();
    let mut ekf = at_rest(noise);
    let v0 = noise.initial_velocity_sigma.powi(2);
    let dt = 0.01;
    for _ in 0..1000 {
        let f = rest_force(&ekf);
        assert!(ekf.predict([0.0; 3], f, dt).is_applied());
    }
    // σ_v²(t) = σ_v0² + q_a t; σ_p²(t) = σ_p0² + σ_v0² t² + q_a t³/3 (discretised to first order).
    let t = 10.0;
    let q = noise.accel_noise_density.powi(2);
    let var_v = ekf.covariance()[(VEL, VEL)];
    assert!(
        ((var_v - (v0 + q * t)) / (v0 + q * t)).abs() < 1e-9,
        "{var_v}"
    );
    let var_p = ekf.covariance()[(POS, POS)];
    let expected = noise.initial_position_sigma.powi(2) + v0 * t * t + q * t.powi(3) / 3.0;
    assert!(
        ((var_p - expected) / expected).abs() < 0.01,
        "{var_p} vs {expected}"
    );
}

#[test]
fn a_zero_velocity_update_removes_the_velocity_in_proportion_to_the_variances() {
    let noise = EkfNoise {
        initial_velocity_sigma: 2.0,
        ..quiet_noise()
    };
    let mut ekf = at_rest(noise);
    let v = Vector3::new(1.0, -0.5, 0.2);
    ekf.state_mut().velocity_ned = v;
    let r: f64 = 0.1;
    let outcome = ekf.zupt(r, 1e6);
    assert!(outcome.is_accepted());
    // Uncorrelated axes: v⁺ = v · R / (P + R), P⁺ = P R / (P + R).
    let (p, rr) = (4.0, r * r);
    let after = ekf.state().velocity_ned;
    for k in 0..3 {
        assert!((after[k] - v[k] * rr / (p + rr)).abs() < 1e-9, "{after}");
        let var = ekf.covariance()[(VEL + k, VEL + k)];
        assert!((var - p * rr / (p + rr)).abs() < 1e-9, "{var}");
    }
    assert_eq!(ekf.counts(AidingSource::Zupt).accepted, 1);
    // Repeated updates drive the velocity to zero.
    for _ in 0..20 {
        let _ = ekf.zupt(r, 1e6);
    }
    assert!(ekf.state().velocity_ned.norm() < 1e-3);
}

#[test]
fn heading_updates_converge_as_the_scalar_kalman_filter() {
    let noise = EkfNoise {
        initial_heading_sigma: 30f64.to_radians(),
        ..quiet_noise()
    };
    let mut ekf = at_rest(noise);
    // Nominal heading 20° off the measured 0°.
    ekf.state_mut().attitude = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.35);
    let sigma = 2f64.to_radians();
    let mut p = 30f64.to_radians().powi(2);
    let mut err: f64 = 0.35;
    for _ in 0..5 {
        assert!(
            ekf.heading(AidingSource::Mag, 0.0, sigma, 10.0)
                .is_accepted()
        );
        // Scalar filter on the heading error.
        let k = p / (p + sigma * sigma);
        err *= 1.0 - k;
        p *= 1.0 - k;
        let yaw = ekf.state().euler()[2];
        assert!((yaw - err).abs() < 1e-3, "yaw {yaw} vs {err}");
    }
    assert!((ekf.sigma(2) - p.sqrt()).abs() < 1e-6);
}

#[test]
fn an_outlier_is_gated_and_counted() {
    let mut ekf = at_rest(quiet_noise());
    let before = ekf.state().alt;
    // σ_h² = 1 + 1 → 100 m off is 70 σ.
    let outcome = ekf.height(before + 100.0, 1.0, 5.0);
    assert!(!outcome.is_accepted());
    assert_eq!(ekf.state().alt, before);
    assert!(ekf.height(before + 1.0, 1.0, 5.0).is_accepted());
    // Equal variances: half the innovation.
    assert!((ekf.state().alt - (before + 0.5)).abs() < 1e-9);
    let c = ekf.counts(AidingSource::Baro);
    assert_eq!((c.accepted, c.rejected), (1, 1));
    // NaN never passes.
    assert!(!ekf.height(f64::NAN, 1.0, 5.0).is_accepted());
}

#[test]
fn the_heading_jacobian_matches_finite_differences_when_tilted() {
    let q = UnitQuaternion::from_euler_angles(0.4, -0.3, 2.0);
    let c = q.to_rotation_matrix().into_inner();
    let jac = heading_jacobian(&c);
    let yaw = |m: &nalgebra::Matrix3<f64>| m[(1, 0)].atan2(m[(0, 0)]);
    for k in 0..3 {
        let mut d = Vector3::zeros();
        d[k] = 1e-7;
        let perturbed = UnitQuaternion::from_scaled_axis(d)
            .to_rotation_matrix()
            .into_inner()
            * c;
        let numeric = (yaw(&perturbed) - yaw(&c)) / 1e-7;
        assert!(
            (numeric - jac[k]).abs() < 1e-5,
            "axis {k}: {numeric} vs {}",
            jac[k]
        );
    }
}

#[test]
fn static_filter_with_zero_velocity_updates_stays_bounded_and_learns_tilt() {
    // Start 2° off in roll; ZUPTs at every sample make the tilt observable through δv' = −[fⁿ×]δθ.
    let noise = EkfNoise::default();
    let mut ekf = at_rest(noise);
    ekf.state_mut().attitude = UnitQuaternion::from_euler_angles(0.035, 0.0, 0.0);
    for _ in 0..3000 {
        let g = ekf.strapdown().gravity();
        assert!(ekf.predict([0.0; 3], [0.0, 0.0, -g], 0.005).is_applied());
        let _ = ekf.zupt(0.01, 1e3);
    }
    let [roll, pitch, _] = ekf.state().euler();
    // Accelerometer bias and tilt are not separable at rest: a roll φ and a y bias g·tan φ give
    // the same specific force, so only their combination must come out right.
    let tilt_equivalent = roll - ekf.bias().accel_mps2.y / G;
    assert!(
        tilt_equivalent.abs() < 1e-3,
        "roll {roll}, bias {:?}",
        ekf.bias().accel_mps2
    );
    assert!(pitch.abs() < 1e-3);
    assert!(ekf.state().velocity_ned.norm() < 1e-3);
    // Velocity σ bounded by the ZUPT noise.
    assert!(ekf.sigma(VEL) < 0.01);
}

/// A tilt error of a filter that believes its tilt poorly (σ 30°) is removed by one gravity update
/// of a precise force (σ 1e-4 m/s²) to the linearisation's second order (ε² = 7.6e-5 rad for
/// ε = 0.5°), whatever the heading, and the heading is left alone to the same order.
#[test]
fn a_gravity_update_removes_a_tilt_error_and_leaves_the_heading() {
    use rins_navigator::ekf::ATT;
    for yaw_deg in [0.0f64, 75.0, -140.0] {
        let truth = UnitQuaternion::from_euler_angles(0.02, -0.01, yaw_deg.to_radians());
        let mut ekf = at_rest(quiet_noise());
        let error =
            UnitQuaternion::from_euler_angles(0.5f64.to_radians(), -0.3f64.to_radians(), 0.0);
        ekf.state_mut().attitude = error * truth;
        for i in ATT..ATT + 2 {
            ekf.reset_component(i, 30f64.to_radians().powi(2));
        }
        let g = ekf.strapdown().gravity();
        let force = truth.inverse() * Vector3::new(0.0, 0.0, -g);
        let outcome = ekf.gravity_tilt(force.into(), 1e-4, f64::INFINITY);
        assert!(outcome.is_accepted(), "{outcome:?}");
        let residual = ekf.state().attitude * truth.inverse();
        let (r, p, y) = residual.euler_angles();
        let second_order = 0.5f64.to_radians().powi(2);
        assert!(
            r.abs() < second_order && p.abs() < second_order,
            "yaw {yaw_deg}: {r} {p}"
        );
        assert!(y.abs() < second_order, "heading moved by {y}");
        assert!(ekf.sigma(ATT) < 1e-4 / g * 1.01, "σ {}", ekf.sigma(ATT));
        assert_eq!(ekf.counts(AidingSource::Gravity).accepted, 1);
    }
}
