//! The aiding measurements: each linearises its measurement (`h`, the innovation, `R`) and
//! hands it to [`ErrorStateEkf::apply`].

use nalgebra::{Matrix3, SMatrix, SVector, Vector1};

use super::filter::{AidingSource, ErrorStateEkf, UpdateOutcome, skew};
use super::linearised::Linearised;
use super::{ATT, BA, POS, STATES, VEL};
use crate::attitude::wrap_pi;

/// `∂ψ/∂δθ` for the yaw `ψ = atan2(C₁₀, C₀₀)` of `C = (I + [δθ×]) Ĉ`: with `[δθ×]` acting on Ĉ's
/// first column, `dC₁₀ = δθ_z Ĉ₀₀ − δθ_x Ĉ₂₀` and `dC₀₀ = −δθ_z Ĉ₁₀ + δθ_y Ĉ₂₀`. Level, it is
/// `[0, 0, 1]`; tilted, roll and pitch errors move the heading too.
pub fn heading_jacobian(c: &Matrix3<f64>) -> [f64; 3] {
    let (c00, c10, c20) = (c[(0, 0)], c[(1, 0)], c[(2, 0)]);
    let n = c00 * c00 + c10 * c10;
    if n < 1e-12 {
        // Pointing straight up or down: heading undefined.
        return [0.0; 3];
    }
    // dψ = (C₀₀ dC₁₀ − C₁₀ dC₀₀) / n
    [-c00 * c20 / n, -c10 * c20 / n, (c00 * c00 + c10 * c10) / n]
}

impl ErrorStateEkf {
    /// Zero-velocity update: `z = 0`, `h = [0 I 0 0 0]`, each axis with σ `sigma_mps`.
    pub fn zupt(&mut self, sigma_mps: f64, gate: f64) -> UpdateOutcome {
        let mut h = SMatrix::<f64, 3, STATES>::zeros();
        h.fixed_view_mut::<3, 3>(0, VEL)
            .copy_from(&Matrix3::identity());
        let innovation = -self.state().velocity_ned;
        let r = Matrix3::identity() * (sigma_mps * sigma_mps);
        self.apply(AidingSource::Zupt, &Linearised { h, innovation, r }, gate)
    }

    /// Height measurement (barometric altitude), m, σ `sigma_m`: `δh = −δp_D`.
    pub fn height(&mut self, height_m: f64, sigma_m: f64, gate: f64) -> UpdateOutcome {
        let mut h = SMatrix::<f64, 1, STATES>::zeros();
        h[(0, POS + 2)] = -1.0;
        let innovation = Vector1::new(height_m - self.state().alt);
        let r = SMatrix::from(Vector1::new(sigma_m * sigma_m));
        self.apply(AidingSource::Baro, &Linearised { h, innovation, r }, gate)
    }

    /// Tilt from gravity: the mean specific force `force_body` (m/s², FRD, as measured) of a
    /// vehicle that is not accelerating points straight up, so its horizontal components in the
    /// navigation frame are zero, each with σ `sigma_mps2`. With the true attitude
    /// `C = (I + [δθ×]) Ĉ` and the true force `f̂ − δb_a` (f̂ bias-corrected), the predicted
    /// horizontal force `Ĉ f̂` moves by `δθ × fⁿ − Ĉ δb_a`; with `fⁿ ≈ [0, 0, −g]` that is
    /// `[−g δθ_y, g δθ_x]` from the tilt errors (the heading term vanishes with the horizontal
    /// force) and the first two rows of `−Ĉ` from the bias.
    pub fn gravity_tilt(
        &mut self,
        force_body: [f64; 3],
        sigma_mps2: f64,
        gate: f64,
    ) -> UpdateOutcome {
        self.gravity_tilt_accelerating(force_body, [0.0; 3], sigma_mps2, gate)
    }

    /// [`Self::gravity_tilt`] for a vehicle whose acceleration `acceleration_ned` (m/s², NED) is
    /// known, e.g. the centripetal acceleration of a turn: the specific force is then `a − g`, and
    /// its horizontal part less `a` is the measurement of zero. `a` is taken as exact (its error
    /// belongs in σ).
    pub fn gravity_tilt_accelerating(
        &mut self,
        force_body: [f64; 3],
        acceleration_ned: [f64; 3],
        sigma_mps2: f64,
        gate: f64,
    ) -> UpdateOutcome {
        let c = self.state().attitude.to_rotation_matrix().into_inner();
        let corrected = nalgebra::Vector3::from(force_body) - self.bias().accel_mps2;
        let f_n = c * corrected;
        let mut h = SMatrix::<f64, 2, STATES>::zeros();
        // Rows of δθ × fⁿ: [δθ_y f_z − δθ_z f_y, δθ_z f_x − δθ_x f_z].
        h[(0, ATT + 1)] = f_n.z;
        h[(0, ATT + 2)] = -f_n.y;
        h[(1, ATT)] = -f_n.z;
        h[(1, ATT + 2)] = f_n.x;
        for k in 0..3 {
            h[(0, BA + k)] = -c[(0, k)];
            h[(1, BA + k)] = -c[(1, k)];
        }
        let innovation =
            SVector::<f64, 2>::new(acceleration_ned[0] - f_n.x, acceleration_ned[1] - f_n.y);
        let r = SMatrix::<f64, 2, 2>::identity() * (sigma_mps2 * sigma_mps2);
        self.apply(
            AidingSource::Gravity,
            &Linearised { h, innovation, r },
            gate,
        )
    }

    /// Rotor drag of a multirotor (as PX4's EKF2 models it): the specific force along the body x
    /// and y axes is the drag `−μ v_b` of the body-frame velocity through still air (the thrust acts
    /// along z only), plus the accelerometer bias; `force_body` is the measured (mean) specific
    /// force, each of x and y with σ `sigma_mps2`; `drag_per_s` holds μ for x and for y. With `v_b = Cᵀ v` and `C = (I + [δθ×]) Ĉ`,
    /// `v_b ≈ Ĉᵀ v̂ + Ĉᵀ δv + Ĉᵀ [v̂×] δθ`: a tilt error shows through the velocity it makes the
    /// filter integrate, which the drag measures, so tilt and the horizontal gyro biases become
    /// observable without any position aiding.
    ///
    /// The model also ties the heading to the direction of the velocity through the air. The
    /// filter's velocity is over the ground, so a wind of w at airspeed v turns that heading by up
    /// to w / v rad (11° for 1 m/s across a 5 m/s flight). With `heading` false the update's
    /// heading column (the vertical component of δθ) is zeroed: the drag then says nothing about
    /// heading, and a GNSS-aided filter no longer turns the wind into heading error and that into
    /// tilt error.
    pub fn rotor_drag(
        &mut self,
        force_body: [f64; 3],
        drag_per_s: [f64; 2],
        sigma_mps2: f64,
        heading: bool,
        gate: f64,
    ) -> UpdateOutcome {
        let c = self.state().attitude.to_rotation_matrix().into_inner();
        let v = self.state().velocity_ned;
        let ct = c.transpose();
        let v_body = ct * v;
        let ct_vx = ct * skew(&v);
        let b = self.bias().accel_mps2;
        let mut h = SMatrix::<f64, 2, STATES>::zeros();
        let mut innovation = SVector::<f64, 2>::zeros();
        for (k, mu) in drag_per_s.into_iter().enumerate() {
            for j in 0..3 {
                h[(k, VEL + j)] = -mu * ct[(k, j)];
                h[(k, ATT + j)] = -mu * ct_vx[(k, j)];
            }
            if !heading {
                h[(k, ATT + 2)] = 0.0;
            }
            h[(k, BA + k)] = 1.0;
            innovation[k] = force_body[k] - (b[k] - mu * v_body[k]);
        }
        let r = SMatrix::<f64, 2, 2>::identity() * (sigma_mps2 * sigma_mps2);
        self.apply(
            AidingSource::Gravity,
            &Linearised { h, innovation, r },
            gate,
        )
    }

    /// Heading measurement, rad from north, σ `sigma_rad` (magnetometer heading, or the stance
    /// heading of a HUPT); the innovation is wrapped to (−π, π].
    pub fn heading(
        &mut self,
        source: AidingSource,
        heading_rad: f64,
        sigma_rad: f64,
        gate: f64,
    ) -> UpdateOutcome {
        let c = self.state().attitude.to_rotation_matrix().into_inner();
        let psi = c[(1, 0)].atan2(c[(0, 0)]);
        let jac = heading_jacobian(&c);
        let mut h = SMatrix::<f64, 1, STATES>::zeros();
        for (k, j) in jac.iter().enumerate() {
            h[(0, ATT + k)] = *j;
        }
        let innovation = SVector::<f64, 1>::new(wrap_pi(heading_rad - psi));
        let r = SMatrix::<f64, 1, 1>::new(sigma_rad * sigma_rad);
        self.apply(source, &Linearised { h, innovation, r }, gate)
    }
}
