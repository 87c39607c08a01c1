//! Mean specific force and rate over a short window of IMU samples: the vibration of an airframe
//! (rotor harmonics of several m/s² from sample to sample) averages out, what is left is the force
//! that tilts or drags the vehicle. Allocation-free.

use nalgebra::Vector3;

/// The mean over one closed window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WindowMean {
    /// Mean specific force, body FRD, m/s² (as measured: no bias removed).
    pub force: Vector3<f64>,
    /// Mean bias-corrected rate, body FRD, rad/s.
    pub rate: Vector3<f64>,
    /// Largest rate magnitude of any sample in the window, rad/s.
    pub max_rate: f64,
    /// Samples averaged.
    pub samples: u32,
}

/// Accumulates samples until `window_s` of device time has passed since the first.
#[derive(Debug, Clone, Copy, Default)]
pub struct ForceWindow {
    start_us: Option<u64>,
    force_sum: Vector3<f64>,
    rate_sum: Vector3<f64>,
    samples: u32,
    max_rate: f64,
}

impl ForceWindow {
    /// Adds one sample at `t_us`; returns the window's mean and starts a new window once the window
    /// spans `window_s`.
    pub fn push(
        &mut self,
        t_us: u64,
        window_s: f64,
        force_body: &Vector3<f64>,
        rate_body: &Vector3<f64>,
    ) -> Option<WindowMean> {
        let start = *self.start_us.get_or_insert(t_us);
        self.force_sum += force_body;
        self.rate_sum += rate_body;
        self.samples += 1;
        self.max_rate = self.max_rate.max(rate_body.norm());
        // Compared in whole microseconds: 0.1 s is 100 000 µs, not a float a hair below it.
        if t_us.saturating_sub(start) < (window_s * 1e6).round() as u64 {
            return None;
        }
        let n = f64::from(self.samples);
        let mean = WindowMean {
            force: self.force_sum / n,
            rate: self.rate_sum / n,
            max_rate: self.max_rate,
            samples: self.samples,
        };
        *self = Self::default();
        Some(mean)
    }

    /// Forgets the samples of the open window.
    pub fn clear(&mut self) {
        *self = Self::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closes_after_the_window_with_the_means_and_the_largest_rate() {
        let mut w = ForceWindow::default();
        let mut out = None;
        for k in 0..=10u64 {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            // ±5 m/s² of vibration about −9.8 on z, rate 0.1 or 0.3 about x.
            let f = Vector3::new(sign * 5.0, 0.0, -9.8);
            let r = Vector3::new(0.2 + sign * 0.1, 0.0, 0.0);
            out = w.push(k * 10_000, 0.1, &f, &r);
            if k < 10 {
                assert!(out.is_none(), "closed early at {k}");
            }
        }
        let m = out.expect("closed at 0.1 s");
        assert_eq!(m.samples, 11);
        // Six +5 and five −5: mean 5/11.
        assert!((m.force.x - 5.0 / 11.0).abs() < 1e-12);
        assert!((m.force.z + 9.8).abs() < 1e-12);
        assert!((m.max_rate - 0.3).abs() < 1e-12);
        // A new window starts with the next sample.
        assert!(
            w.push(200_000, 0.1, &Vector3::zeros(), &Vector3::zeros())
                .is_none()
        );
    }
}
