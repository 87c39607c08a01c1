//! Madgwick's gradient-descent filter (S. O. H. Madgwick, A. J. L. Harrison, R. Vaidyanathan,
//! 2011) and Mahony's explicit complementary filter (R. Mahony, T. Hamel, J.-M. Pflimlin, 2008),
//! both in their IMU form: body rate and specific force, no magnetometer.
//!
//! Both hold the body → earth rotation `q` of an earth frame whose z axis points up, along the
//! specific force at rest, so that the force's direction measures `q⁻¹ · ẑ`. Both integrate
//! `q̇ = ½ q ⊗ (0, ω)` with one explicit Euler step per sample and then normalise `q`; the
//! specific force is normalised before it is compared with the estimate. A zero specific force has
//! no direction: the sample then only integrates the measured rate (Mahony's integral term
//! neither grows nor is applied), which is what the `ahrs` crate 0.8.0 does, so that the two
//! agree sample for sample.

use nalgebra::{Quaternion, UnitQuaternion, Vector3, Vector4};

/// What one update could use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Correction {
    /// The specific force's direction corrected the attitude (by nothing where it already agreed).
    FromForce,
    /// The specific force was zero: only the rate was integrated.
    RateOnly,
}

/// `q̇ = ½ q ⊗ (0, ω)`: the rate of change of a body → earth quaternion under body rate `ω`.
fn attitude_rate(attitude: &Quaternion<f64>, rate_rps: &Vector3<f64>) -> Quaternion<f64> {
    (attitude * Quaternion::from_parts(0.0, *rate_rps)) * 0.5
}

/// One explicit Euler step of `dt_s`, normalised back onto the unit sphere.
fn euler_step(
    attitude: &Quaternion<f64>,
    attitude_rate: &Quaternion<f64>,
    dt_s: f64,
) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(attitude + attitude_rate * dt_s)
}

/// Madgwick's filter: the rate integration is pulled down the normalised gradient of the
/// misfit between the measured and the predicted direction of the specific force, at rate β.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MadgwickImu {
    sample_period_s: f64,
    beta_rps: f64,
    attitude: UnitQuaternion<f64>,
}

impl MadgwickImu {
    /// A filter stepping `sample_period_s` per sample with gain `beta_rps`, started at
    /// `attitude` (body → up-frame).
    pub fn new(sample_period_s: f64, beta_rps: f64, attitude: UnitQuaternion<f64>) -> Self {
        Self {
            sample_period_s,
            beta_rps,
            attitude,
        }
    }

    /// The current attitude, body → up-frame.
    pub fn attitude(&self) -> UnitQuaternion<f64> {
        self.attitude
    }

    /// Applies one sample of body rate (rad/s) and specific force (any unit).
    pub fn update(&mut self, rate_rps: &Vector3<f64>, force: &Vector3<f64>) -> Correction {
        let q = *self.attitude.quaternion();
        let Some(down_to_up) = force.try_normalize(0.0) else {
            self.attitude = euler_step(&q, &attitude_rate(&q, rate_rps), self.sample_period_s);
            return Correction::RateOnly;
        };
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        // The paper's objective f = q⁻¹ ẑ q − a (its eq. 25 with the earth reference (0, 0, 1)),
        // written as the paper expands it; the last row stands where the magnetometer's would.
        let misfit = [
            2.0 * (x * z - w * y) - down_to_up.x,
            2.0 * (w * x + y * z) - down_to_up.y,
            2.0 * (0.5 - x * x - y * y) - down_to_up.z,
        ];
        // ∇f = Jᵀ f with the paper's Jacobian (its eq. 26), in (w, x, y, z) order.
        let gradient = Vector4::new(
            -2.0 * y * misfit[0] + 2.0 * x * misfit[1],
            2.0 * z * misfit[0] + 2.0 * w * misfit[1] - 4.0 * x * misfit[2],
            -2.0 * w * misfit[0] + 2.0 * z * misfit[1] - 4.0 * y * misfit[2],
            2.0 * x * misfit[0] + 2.0 * y * misfit[1],
        );
        let rate = attitude_rate(&q, rate_rps);
        // A zero gradient is an estimate that already agrees with the force: nothing to correct.
        let Some(step) = gradient.try_normalize(0.0) else {
            self.attitude = euler_step(&q, &rate, self.sample_period_s);
            return Correction::FromForce;
        };
        let descent = Quaternion::new(step[0], step[1], step[2], step[3]) * self.beta_rps;
        self.attitude = euler_step(&q, &(rate - descent), self.sample_period_s);
        Correction::FromForce
    }
}

/// Mahony's explicit complementary filter: the cross product of the measured and the predicted
/// direction of the specific force is fed back into the rate, proportionally and through an
/// integrator that learns a constant gyro bias.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MahonyImu {
    sample_period_s: f64,
    kp_rps: f64,
    ki_rps2: f64,
    error_integral: Vector3<f64>,
    attitude: UnitQuaternion<f64>,
}

impl MahonyImu {
    /// A filter stepping `sample_period_s` per sample with proportional gain `kp_rps` and
    /// integral gain `ki_rps2`, started at `attitude` (body → up-frame) with an empty integrator.
    pub fn new(
        sample_period_s: f64,
        kp_rps: f64,
        ki_rps2: f64,
        attitude: UnitQuaternion<f64>,
    ) -> Self {
        Self {
            sample_period_s,
            kp_rps,
            ki_rps2,
            error_integral: Vector3::zeros(),
            attitude,
        }
    }

    /// The current attitude, body → up-frame.
    pub fn attitude(&self) -> UnitQuaternion<f64> {
        self.attitude
    }

    /// The integrated direction error; times `ki` it is the filter's estimate of minus the gyro
    /// bias, rad/s.
    pub fn error_integral(&self) -> Vector3<f64> {
        self.error_integral
    }

    /// Applies one sample of body rate (rad/s) and specific force (any unit).
    pub fn update(&mut self, rate_rps: &Vector3<f64>, force: &Vector3<f64>) -> Correction {
        let q = *self.attitude.quaternion();
        let Some(measured_up) = force.try_normalize(0.0) else {
            self.attitude = euler_step(&q, &attitude_rate(&q, rate_rps), self.sample_period_s);
            return Correction::RateOnly;
        };
        let (w, x, y, z) = (q.w, q.i, q.j, q.k);
        // The up direction the estimate predicts in the body frame, v̂ = R(q)ᵀ ẑ.
        let predicted_up = Vector3::new(
            2.0 * (x * z - w * y),
            2.0 * (w * x + y * z),
            w * w - x * x - y * y + z * z,
        );
        // The paper's ω_mes = v × v̂ turns the estimate towards the measurement.
        let error = measured_up.cross(&predicted_up);
        self.error_integral += error * self.sample_period_s;
        let corrected_rate = *rate_rps + error * self.kp_rps + self.error_integral * self.ki_rps2;
        self.attitude = euler_step(
            &q,
            &attitude_rate(&q, &corrected_rate),
            self.sample_period_s,
        );
        Correction::FromForce
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f64 = 0.01;
    const G: f64 = 9.81;

    /// The up direction at rest in the body frame of `attitude` (body → up-frame).
    fn force_at_rest(attitude: &UnitQuaternion<f64>) -> Vector3<f64> {
        attitude.inverse() * Vector3::new(0.0, 0.0, G)
    }

    /// Turning at a constant rate about z while the force stays along z: the force agrees with
    /// the estimate at every step, so both filters integrate the rate alone. One Euler step
    /// followed by normalisation turns by 2·atan(ω dt / 2), short of ω dt by (ω dt)³/12.
    #[test]
    fn a_constant_rotation_about_the_vertical_turns_by_the_integrated_angle() {
        let (rate, n) = (0.5, 1000);
        let omega = Vector3::new(0.0, 0.0, rate);
        let force = Vector3::new(0.0, 0.0, G);
        let expected = n as f64 * 2.0 * (rate * DT / 2.0).atan();
        let mut madgwick = MadgwickImu::new(DT, 0.1, UnitQuaternion::identity());
        let mut mahony = MahonyImu::new(DT, 0.5, 0.1, UnitQuaternion::identity());
        for _ in 0..n {
            assert_eq!(madgwick.update(&omega, &force), Correction::FromForce);
            assert_eq!(mahony.update(&omega, &force), Correction::FromForce);
        }
        for attitude in [madgwick.attitude(), mahony.attitude()] {
            let (roll, pitch, yaw) = attitude.euler_angles();
            assert!(roll.abs() < 1e-12 && pitch.abs() < 1e-12, "{roll} {pitch}");
            let error = (yaw - expected + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                - std::f64::consts::PI;
            assert!(error.abs() < 1e-9, "{yaw} vs {expected}");
        }
        assert!(mahony.error_integral().norm() < 1e-12);
    }

    /// Resting level, started 10° off in roll: Madgwick turns towards the force at 2β rad/s
    /// (a normalised step of β on the quaternion) until it dithers within one step, 2β dt, of it;
    /// Mahony's error decays as e^(−kp t) for small angles.
    #[test]
    fn a_static_tilt_error_converges_to_the_force() {
        let start = UnitQuaternion::from_euler_angles(10_f64.to_radians(), 0.0, 0.0);
        let force = Vector3::new(0.0, 0.0, G);
        let still = Vector3::zeros();
        let (beta, kp, n) = (0.1, 0.5, 2000);
        let mut madgwick = MadgwickImu::new(DT, beta, start);
        let mut mahony = MahonyImu::new(DT, kp, 0.0, start);
        for _ in 0..n {
            madgwick.update(&still, &force);
            mahony.update(&still, &force);
        }
        let tilt = |q: UnitQuaternion<f64>| {
            let (roll, pitch, _) = q.euler_angles();
            roll.hypot(pitch)
        };
        let madgwick_tilt = tilt(madgwick.attitude());
        assert!(madgwick_tilt < 2.0 * beta * DT, "Madgwick {madgwick_tilt}");
        let mahony_tilt = tilt(mahony.attitude());
        let decayed = 10_f64.to_radians() * (-kp * n as f64 * DT).exp();
        assert!(
            mahony_tilt < 1.5 * decayed,
            "Mahony {mahony_tilt} vs {decayed}"
        );
    }

    /// A constant gyro bias b at rest, tilted: the integrator settles where ki times the error
    /// integral cancels b, after which the error and the attitude's drift vanish. Linearised, the
    /// tilt error e obeys ë + kp ė + ki e = 0, whose slower root is s = (kp − √(kp² − 4 ki)) / 2;
    /// after twenty of its time constants what is left of the start (a few times |b| / ki in the
    /// integral) is below e⁻²⁰, so the bias estimate must hold to 1e-6 |b|. The bias about the
    /// vertical is unobservable from the force and stays uncorrected, so it is left zero here.
    #[test]
    fn mahonys_integral_term_removes_a_constant_gyro_bias() {
        let attitude = UnitQuaternion::from_euler_angles(0.2, -0.1, 0.7);
        let force = force_at_rest(&attitude);
        // A bias with no component along the force keeps the vertical out of it.
        let raw_bias = Vector3::new(0.01, -0.02, 0.015);
        let up = force.normalize();
        let bias = raw_bias - up * up.dot(&raw_bias);
        let (kp, ki): (f64, f64) = (1.0, 0.2);
        let slow_root = (kp - (kp * kp - 4.0 * ki).sqrt()) / 2.0;
        let mut mahony = MahonyImu::new(DT, kp, ki, attitude);
        let n = (20.0 / slow_root / DT) as usize;
        for _ in 0..n {
            mahony.update(&bias, &force);
        }
        let estimate = -(mahony.error_integral() * ki);
        assert!(
            (estimate - bias).norm() < 1e-6 * bias.norm(),
            "{estimate} vs {bias}"
        );
        // With the bias cancelled, the tilt has stopped moving.
        let before = mahony.attitude();
        for _ in 0..100 {
            mahony.update(&bias, &force);
        }
        assert!(before.angle_to(&mahony.attitude()) < 1e-6);
        let tilt_error = (mahony.attitude().inverse() * Vector3::z()).angle(&up);
        assert!(tilt_error < 1e-4, "tilt error {tilt_error}");
    }

    #[test]
    fn a_zero_force_only_integrates_the_rate() {
        let omega = Vector3::new(0.1, -0.2, 0.3);
        let start = UnitQuaternion::from_euler_angles(0.3, 0.2, 0.1);
        let expected = euler_step(
            start.quaternion(),
            &attitude_rate(start.quaternion(), &omega),
            DT,
        );
        let mut madgwick = MadgwickImu::new(DT, 0.1, start);
        assert_eq!(
            madgwick.update(&omega, &Vector3::zeros()),
            Correction::RateOnly
        );
        assert_eq!(madgwick.attitude(), expected);
        let mut mahony = MahonyImu::new(DT, 0.5, 0.1, start);
        assert_eq!(
            mahony.update(&omega, &Vector3::zeros()),
            Correction::RateOnly
        );
        assert_eq!(mahony.attitude(), expected);
        assert_eq!(mahony.error_integral(), Vector3::zeros());
    }
}
