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
use crate::force_window::ForceWindow;
use crate::integrity::IntegrityConfig;

/// Re-levelling after a loss of attitude.
#[derive(Debug, Clone, Default)]
pub struct AttitudeRecovery {
    lost: bool,
    window: ForceWindow,
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
        self.window.clear();
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
        let mean = self.window.push(
            t_us,
            config.gravity_window_s,
            &Vector3::from(force_body),
            rate_body,
        )?;
        let quiet = (mean.force.norm() - ekf.strapdown().gravity()).abs()
            <= config.gravity_force_tolerance_mps2
            && mean.max_rate <= config.gravity_max_rate_dps.to_radians();
        if !quiet {
            return None;
        }
        let outcome = ekf.gravity_tilt(mean.force.into(), config.gravity_sigma_mps2, f64::INFINITY);
        let tilt = ekf.sigma(ATT).max(ekf.sigma(ATT + 1));
        if tilt <= config.relevelled_tilt_sigma_deg.to_radians() {
            self.lost = false;
        }
        Some(outcome)
    }
}
