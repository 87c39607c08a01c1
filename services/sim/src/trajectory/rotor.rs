//! The rotors' blade-pass phase: the angle the rotor vibration (see
//! [`crate::sensor_model::vibration`]) turns through, the integral of a blade-pass frequency that
//! follows the thrust.
//!
//! Rotor speed goes as the square root of the thrust, so the blade-pass frequency is its hover
//! value times √(T/g), held within ±20 % (what a quadrotor's motors span between a gentle descent
//! and a hard climbing turn). The frequency has no closed-form integral, so the phase is tabulated
//! on a grid and, between knots, the frequency is taken as linear: the phase is then exact to the
//! frequency's curvature over one grid step, far below a radian.

use std::f64::consts::TAU;

use rins_earth::STANDARD_GRAVITY;

/// Rotor-speed span around the hover value.
const MIN_SPEED_RATIO: f64 = 0.8;
const MAX_SPEED_RATIO: f64 = 1.2;

/// Blade-pass frequency, Hz, of a rotor whose hover blade-pass frequency is `hover_hz`, at a thrust
/// of `thrust_mps2` per unit mass.
pub fn blade_pass_hz(hover_hz: f64, thrust_mps2: f64) -> f64 {
    let ratio = (thrust_mps2.max(0.0) / STANDARD_GRAVITY).sqrt();
    hover_hz * ratio.clamp(MIN_SPEED_RATIO, MAX_SPEED_RATIO)
}

/// Blade-pass phase on a time grid.
#[derive(Debug, Clone)]
pub struct BladePhase {
    start_s: f64,
    spacing_s: f64,
    /// Per knot: [phase (rad), frequency (Hz)].
    knots: Vec<[f64; 2]>,
}

impl BladePhase {
    /// Rotors that never turn: the phase stays 0.
    pub fn off() -> Self {
        Self {
            start_s: 0.0,
            spacing_s: 1.0,
            knots: vec![[0.0, 0.0]],
        }
    }

    /// Integrates the blade-pass frequency of `hover_hz` at the thrust `thrust_mps2(t)` from
    /// `start_s` (phase 0) to `end_s` on a grid of `spacing_s`.
    pub fn integrate(
        start_s: f64,
        end_s: f64,
        spacing_s: f64,
        hover_hz: f64,
        thrust_mps2: impl Fn(f64) -> f64,
    ) -> Self {
        // Whole number of intervals covering the span (NaN and negative spans give one).
        let intervals = ((end_s - start_s).max(0.0) / spacing_s).ceil() as usize + 1;
        let mut knots = Vec::with_capacity(intervals + 1);
        let mut phase = 0.0;
        let mut previous_hz = blade_pass_hz(hover_hz, thrust_mps2(start_s));
        knots.push([phase, previous_hz]);
        for i in 1..=intervals {
            let hz = blade_pass_hz(hover_hz, thrust_mps2(start_s + i as f64 * spacing_s));
            phase += TAU * 0.5 * (previous_hz + hz) * spacing_s;
            knots.push([phase, hz]);
            previous_hz = hz;
        }
        Self {
            start_s,
            spacing_s,
            knots,
        }
    }

    /// Phase at `t`, rad (not wrapped); 0 before the table, growing at the last frequency after.
    pub fn sample(&self, t: f64) -> f64 {
        let x = (t - self.start_s) / self.spacing_s;
        if x.is_nan() || x <= 0.0 {
            return 0.0;
        }
        let last = self.knots.len() - 1;
        if x >= last as f64 {
            let [phase, hz] = self.knots[last];
            return phase + TAU * hz * (t - self.start_s - last as f64 * self.spacing_s);
        }
        let i = x as usize;
        let tau = (x - i as f64) * self.spacing_s;
        let [phase, hz] = self.knots[i];
        let slope = (self.knots[i + 1][1] - hz) / self.spacing_s;
        phase + TAU * (hz * tau + 0.5 * slope * tau * tau)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frequency_follows_the_square_root_of_thrust_within_its_span() {
        assert!((blade_pass_hz(200.0, STANDARD_GRAVITY) - 200.0).abs() < 1e-12);
        let hard = blade_pass_hz(200.0, 1.21 * STANDARD_GRAVITY);
        assert!((hard - 220.0).abs() < 1e-9);
        assert_eq!(blade_pass_hz(200.0, 10.0 * STANDARD_GRAVITY), 240.0);
        assert_eq!(blade_pass_hz(200.0, 0.0), 160.0);
    }

    #[test]
    fn phase_is_the_integral_of_a_linearly_rising_frequency() {
        // Thrust rising so that the frequency goes 200 → 220 Hz linearly over 10 s.
        let thrust = |t: f64| STANDARD_GRAVITY * (1.0 + 0.01 * t).powi(2);
        let table = BladePhase::integrate(0.0, 10.0, 0.01, 200.0, thrust);
        for t in [0.0, 0.005, 1.234, 5.0, 9.999] {
            let exact = TAU * (200.0 * t + 1.0 * t * t);
            assert!((table.sample(t) - exact).abs() < 1e-6, "t={t}");
        }
    }
}
