//! The attitude after the IMU stopped propagating it: an outage (every channel of a type out, a
//! saturated block, rejected frames) or a device clock that stopped leaves the vehicle free to have
//! turned by any amount meanwhile. The filter's attitude is then declared lost — its three error
//! variances set to `lost_attitude_sigma_deg`², correlations dropped — so the covariance says what
//! is known, and the tilt is re-levelled from gravity: over windows of `gravity_window_s` in which
//! the vehicle is quasi-static (mean |f| within `gravity_force_tolerance_mps2` of g, every rate
//! below `gravity_max_rate_dps`), the mean specific force is a tilt measurement
//! ([`ErrorStateEkf::gravity_tilt`]) until the tilt σ is back below `relevelled_tilt_sigma_deg`.
//! The heading comes back from the magnetometer, whose gate the large heading variance opens.
//!
//! Outside such a recovery nothing here acts: the accelerometers are not used as a gravity
//! reference in normal navigation. Allocation-free.

use nalgebra::Vector3;

use crate::ekf::{ATT, ErrorStateEkf, UpdateOutcome};
use crate::integrity::IntegrityConfig;

/// Accumulated specific force and rate of one window.
#[derive(Debug, Clone, Copy, Default)]
struct Window {
    start_us: Option<u64>,
    force_sum: Vector3<f64>,
    samples: u32,
    max_rate: f64,
}

/// Re-levelling after a loss of attitude.
#[derive(Debug, Clone, Default)]
pub struct AttitudeRecovery {
    lost: bool,
    window: Window,
}

impl AttitudeRecovery {
    /// The attitude is being recovered.
    pub fn is_lost(&self) -> bool {
        self.lost
    }

    /// The IMU did not propagate the attitude for a while: it is unknown.
    pub fn lose(&mut self, ekf: &mut ErrorStateEkf, config: &IntegrityConfig) {
        let sigma = config.lost_attitude_sigma_deg.to_radians();
        for i in ATT..ATT + 3 {
            ekf.reset_component(i, sigma * sigma);
        }
        self.lost = true;
        self.window = Window::default();
    }

    /// One propagated IMU sample at `t_us`: specific force as measured and bias-corrected rate.
    /// Returns the gravity update made when a quasi-static window closed.
    pub fn push(
        &mut self,
        ekf: &mut ErrorStateEkf,
        config: &IntegrityConfig,
        t_us: u64,
        force_body: [f64; 3],
        rate_body: &Vector3<f64>,
    ) -> Option<UpdateOutcome> {
        if !self.lost {
            return None;
        }
        let w = &mut self.window;
        let start = *w.start_us.get_or_insert(t_us);
        w.force_sum += Vector3::from(force_body);
        w.samples += 1;
        w.max_rate = w.max_rate.max(rate_body.norm());
        if (t_us.saturating_sub(start) as f64) * 1e-6 < config.gravity_window_s {
            return None;
        }
        let mean = w.force_sum / f64::from(w.samples);
        let quiet = (mean.norm() - ekf.strapdown().gravity()).abs()
            <= config.gravity_force_tolerance_mps2
            && w.max_rate <= config.gravity_max_rate_dps.to_radians();
        self.window = Window::default();
        if !quiet {
            return None;
        }
        let outcome = ekf.gravity_tilt(mean.into(), config.gravity_sigma_mps2, f64::INFINITY);
        let tilt = ekf.sigma(ATT).max(ekf.sigma(ATT + 1));
        if tilt <= config.relevelled_tilt_sigma_deg.to_radians() {
            self.lost = false;
        }
        Some(outcome)
    }
}
