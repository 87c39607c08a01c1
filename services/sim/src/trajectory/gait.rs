//! Closed-form profiles of one swing phase of a foot, and of the load on its pressure sensor.
//!
//! Each profile is a function of the swing phase u = (t − lift-off)/T ∈ [0, 1] and is returned with
//! its first and second time derivatives. Every one starts and ends with zero rate and zero second
//! derivative, so a foot that rests between swings has continuous velocity, acceleration,
//! attitude rate and angular acceleration: the truth can be integrated to sub-millimetre precision
//! and its sampled inertial readings have no artificial steps.

use std::f64::consts::{PI, TAU};

/// A scalar profile and its time derivatives at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Profile {
    /// x(t)
    pub value: f64,
    /// dx/dt
    pub rate: f64,
    /// d²x/dt²
    pub accel: f64,
}

impl Profile {
    /// Scales the value and both derivatives by `k`.
    pub fn scaled(self, k: f64) -> Self {
        Self {
            value: k * self.value,
            rate: k * self.rate,
            accel: k * self.accel,
        }
    }
}

/// Converts derivatives with respect to the phase u into time derivatives for a swing of
/// `duration_s`.
fn in_time(value: f64, d_du: f64, d2_du2: f64, duration_s: f64) -> Profile {
    Profile {
        value,
        rate: d_du / duration_s,
        accel: d2_du2 / (duration_s * duration_s),
    }
}

/// Progress along the stride, 0 → 1: the cycloid σ(u) = u − sin(2πu)/(2π). Its speed
/// (1 − cos 2πu)/T peaks at mid-swing at twice the mean.
pub fn progress(u: f64, duration_s: f64) -> Profile {
    let (s, c) = (TAU * u).sin_cos();
    in_time(u - s / TAU, 1.0 - c, TAU * s, duration_s)
}

/// Foot height, normalised to 1 at mid-swing: sin⁴(πu) = (3 − 4 cos 2πu + cos 4πu)/8. Unlike
/// (1 − cos 2πu)/2 its second derivative also vanishes at the ends, so the vertical acceleration
/// does not jump at lift-off and heel strike.
pub fn lift(u: f64, duration_s: f64) -> Profile {
    let (s1, c1) = (TAU * u).sin_cos();
    let (s2, c2) = (2.0 * TAU * u).sin_cos();
    in_time(
        (3.0 - 4.0 * c1 + c2) / 8.0,
        PI * (2.0 * s1 - s2) / 2.0,
        2.0 * PI * PI * (c1 - c2),
        duration_s,
    )
}

/// Foot pitch, normalised: −k sin³(πu) cos(πu) = −k (2 sin 2πu − sin 4πu)/8, k = 1/max(sin³x cos x)
/// = 16/(3√3). Toe down (−1 at u = 1/3) after toe-off, toe up (+1 at u = 2/3) before heel strike,
/// and rotating fastest through level at mid-swing, k·π/T per unit amplitude, as a real foot does
/// (the shank swings it through): a foot that paused its rotation there while moving at constant
/// speed would read exactly like one standing still to a stance detector.
pub fn pitch(u: f64, duration_s: f64) -> Profile {
    let k = 16.0 / (3.0 * 3f64.sqrt());
    let (s1, c1) = (TAU * u).sin_cos();
    let (s2, c2) = (2.0 * TAU * u).sin_cos();
    in_time(
        -k * (2.0 * s1 - s2) / 8.0,
        -k * TAU * (c1 - c2) / 4.0,
        -k * TAU * TAU * (2.0 * s2 - s1) / 4.0,
        duration_s,
    )
}

/// Load fraction `elapsed_s` after a load change starts, rising smoothly 0 → 1 over `ramp_s` as
/// (1 − cos πr)/2: 0 before, 1 after (∞ elapsed gives 1).
pub fn load_ramp(elapsed_s: f64, ramp_s: f64) -> f64 {
    if elapsed_s >= ramp_s {
        1.0
    } else if elapsed_s > 0.0 {
        0.5 * (1.0 - (PI * elapsed_s / ramp_s).cos())
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: f64 = 0.6;

    fn check_derivatives(f: fn(f64, f64) -> Profile) {
        let h = 1e-6;
        for i in 0..=100 {
            let u = 0.01 * f64::from(i);
            let (lo, mid, hi) = (f(u - h / T, T), f(u, T), f(u + h / T, T));
            let fd_rate = (hi.value - lo.value) / (2.0 * h);
            let fd_accel = (hi.rate - lo.rate) / (2.0 * h);
            assert!((fd_rate - mid.rate).abs() < 1e-6, "rate at u={u}");
            assert!((fd_accel - mid.accel).abs() < 1e-4, "accel at u={u}");
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        check_derivatives(progress);
        check_derivatives(lift);
        check_derivatives(pitch);
    }

    #[test]
    fn profiles_rest_at_both_ends() {
        for f in [progress, lift, pitch] {
            for u in [0.0, 1.0] {
                let p = f(u, T);
                assert!(p.rate.abs() < 1e-12 && p.accel.abs() < 1e-12, "u={u}");
            }
        }
        assert_eq!(progress(0.0, T).value, 0.0);
        assert!((progress(1.0, T).value - 1.0).abs() < 1e-15);
        assert!(lift(0.0, T).value.abs() < 1e-15 && lift(1.0, T).value.abs() < 1e-15);
        assert!((lift(0.5, T).value - 1.0).abs() < 1e-15);
        assert!((pitch(1.0 / 3.0, T).value + 1.0).abs() < 1e-14);
        assert!((pitch(2.0 / 3.0, T).value - 1.0).abs() < 1e-14);
        // Level and rotating fastest at mid-swing: k·π/T toe up.
        let mid = pitch(0.5, T);
        let k = 16.0 / (3.0 * 3f64.sqrt());
        assert!(mid.value.abs() < 1e-15);
        assert!((mid.rate - k * PI / T).abs() < 1e-12, "{}", mid.rate);
    }

    #[test]
    fn load_ramp_is_monotone_from_zero_to_one() {
        assert_eq!(load_ramp(-1.0, 0.05), 0.0);
        assert_eq!(load_ramp(0.0, 0.05), 0.0);
        assert!((load_ramp(0.025, 0.05) - 0.5).abs() < 1e-12);
        assert_eq!(load_ramp(0.05, 0.05), 1.0);
        assert_eq!(load_ramp(f64::INFINITY, 0.05), 1.0);
    }
}
