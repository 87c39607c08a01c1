//! A scalar time schedule made of holds joined by smooth steps.
//!
//! Each step from `a` to `b` over `T` follows the cycloidal profile
//! `s(u) = u − sin(2πu)/(2π)`, whose first and second derivatives vanish at both ends: the value,
//! its rate and its second derivative are all continuous. A schedule of heading rate therefore gives
//! a continuous roll rate (which depends on the heading acceleration), and a speed schedule gives a
//! continuous acceleration. Value, derivative and running integral are all closed form, so sampling
//! needs no integration and no allocation.

use std::f64::consts::TAU;

/// Value of a schedule at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ScheduleSample {
    /// x(t)
    pub value: f64,
    /// dx/dt
    pub rate: f64,
    /// ∫₀ᵗ x dτ
    pub integral: f64,
}

#[derive(Debug, Clone, Copy)]
struct Step {
    start_s: f64,
    duration_s: f64,
    from: f64,
    to: f64,
    /// ∫₀^start x dτ
    integral_at_start: f64,
}

impl Step {
    fn end_s(&self) -> f64 {
        self.start_s + self.duration_s
    }

    fn integral_at_end(&self) -> f64 {
        self.integral_at_start + 0.5 * self.duration_s * (self.from + self.to)
    }
}

/// Piecewise-smooth scalar schedule: holds its value between smooth steps, and holds the last value
/// forever after the last step.
#[derive(Debug, Clone)]
pub struct Schedule {
    initial: f64,
    steps: Vec<Step>,
}

impl Schedule {
    /// A schedule that holds `initial` until the first step.
    pub fn new(initial: f64) -> Self {
        Self {
            initial,
            steps: Vec::new(),
        }
    }

    /// Value held after the last step.
    pub fn final_value(&self) -> f64 {
        self.steps.last().map_or(self.initial, |s| s.to)
    }

    /// Time the last step ends (0 without steps).
    pub fn end_s(&self) -> f64 {
        self.steps.last().map_or(0.0, Step::end_s)
    }

    /// Appends a smooth step to `to` starting at `start_s` and lasting `duration_s`.
    /// Steps must be appended in time order without overlap; `duration_s` must be positive.
    pub fn step_to(&mut self, start_s: f64, duration_s: f64, to: f64) {
        debug_assert!(duration_s > 0.0);
        debug_assert!(start_s >= self.end_s() - 1e-12);
        let (from, integral_at_start) = match self.steps.last() {
            Some(prev) => (
                prev.to,
                prev.integral_at_end() + prev.to * (start_s - prev.end_s()),
            ),
            None => (self.initial, self.initial * start_s),
        };
        self.steps.push(Step {
            start_s,
            duration_s,
            from,
            to,
            integral_at_start,
        });
    }

    /// Samples value, derivative and integral at `t` (seconds, t ≥ 0).
    pub fn sample(&self, t: f64) -> ScheduleSample {
        let idx = self.steps.partition_point(|s| s.start_s <= t);
        if idx == 0 {
            return ScheduleSample {
                value: self.initial,
                rate: 0.0,
                integral: self.initial * t,
            };
        }
        let step = &self.steps[idx - 1];
        let tau = t - step.start_s;
        if tau >= step.duration_s {
            return ScheduleSample {
                value: step.to,
                rate: 0.0,
                integral: step.integral_at_end() + step.to * (tau - step.duration_s),
            };
        }
        let u = tau / step.duration_s;
        let delta = step.to - step.from;
        let (sin, cos) = (TAU * u).sin_cos();
        let s = u - sin / TAU;
        let ds = 1.0 - cos;
        let big_s = 0.5 * u * u + (cos - 1.0) / (TAU * TAU);
        ScheduleSample {
            value: step.from + delta * s,
            rate: delta * ds / step.duration_s,
            integral: step.integral_at_start + step.from * tau + delta * step.duration_s * big_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn schedule() -> Schedule {
        let mut s = Schedule::new(1.0);
        s.step_to(2.0, 3.0, 4.0);
        s.step_to(7.0, 0.5, -2.0);
        s
    }

    #[test]
    fn holds_and_reaches_targets() {
        let s = schedule();
        assert_eq!(s.sample(0.0).value, 1.0);
        assert_eq!(s.sample(2.0).value, 1.0);
        assert!((s.sample(5.0).value - 4.0).abs() < 1e-12);
        assert!((s.sample(6.0).value - 4.0).abs() < 1e-12);
        assert!((s.sample(100.0).value + 2.0).abs() < 1e-12);
        assert!(
            (s.sample(3.5).value - 2.5).abs() < 1e-12,
            "midpoint of a step is the mean"
        );
    }

    #[test]
    fn integral_matches_closed_form_areas() {
        let s = schedule();
        // 1·2 + 3·(1+4)/2 + 4·2 + 0.5·(4−2)/2 + (−2)·2.5
        let expected = 2.0 + 7.5 + 8.0 + 0.5 + (-5.0);
        assert!((s.sample(10.0).integral - expected).abs() < 1e-12);
    }

    #[test]
    fn derivative_and_integral_agree_with_finite_differences() {
        let s = schedule();
        let h = 1e-5;
        for i in 0..1000 {
            let t = 0.01 * f64::from(i) + 0.0013;
            let (lo, mid, hi) = (s.sample(t - h), s.sample(t), s.sample(t + h));
            let fd_rate = (hi.value - lo.value) / (2.0 * h);
            let fd_value = (hi.integral - lo.integral) / (2.0 * h);
            assert!(
                (fd_rate - mid.rate).abs() < 1e-5,
                "rate at t={t}: {fd_rate} vs {}",
                mid.rate
            );
            assert!((fd_value - mid.value).abs() < 1e-6, "value at t={t}");
        }
    }

    #[test]
    fn value_and_rate_are_continuous_at_step_edges() {
        let s = schedule();
        for edge in [2.0, 5.0, 7.0, 7.5] {
            let (a, b) = (s.sample(edge - 1e-9), s.sample(edge + 1e-9));
            assert!((a.value - b.value).abs() < 1e-7);
            assert!((a.rate - b.rate).abs() < 1e-6, "rate jumps at {edge}");
        }
    }
}
