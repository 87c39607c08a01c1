//! A fault among the redundant IMU channels that fusion has detected but not yet isolated.
//!
//! Between detection and isolation the fused solution still includes the channel that disagrees.
//! With four gyros on skewed axes the parity space has one dimension: a bias on any channel moves
//! the parity along the same line, so parity detects it at once but cannot say which channel it
//! is; isolation then waits for another reference (the stationary reference at rest). Meanwhile
//! the fused rate is wrong by up to the bound fusion adds to the rate variance (the largest rate
//! error any of the candidate channels' fault can cause, see the fusion monitor), and the attitude
//! integrates that error.
//!
//! The navigator therefore (1) says so: the integrity is degraded (`sensor-fault-unisolated`)
//! while the fault is unisolated; and (2) widens the attitude covariance by the error the fault
//! may have integrated, `B = Σ r·Δt` with `r` the rate bound, so that the filter's σ covers it (a
//! bias integrates linearly, which the white-noise propagation of the rate variance would not
//! cover). Once the fault is isolated (or the parity returns), the integrity stays degraded while
//! the widened attitude σ is above its limit
//! ([`crate::integrity::IntegrityConfig::fault_attitude_sigma_deg`]); and when the episode's bound
//! `B` itself exceeded the limit, for as long as this filter runs: without horizontal aiding the
//! tilt is weakly observable, a gravity re-levelling in flight takes any acceleration for tilt,
//! and the aiding that shrinks the σ afterwards has been seen to leave several degrees of error.

use ipc_types::fused_flags;

/// Fusion's fault report of one fused IMU sample, as the navigator uses it.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FusionFault {
    /// A gyro fault is detected and not isolated.
    pub gyro_unisolated: bool,
    /// An accelerometer fault is detected and not isolated.
    pub accel_unisolated: bool,
    /// The largest rate error the unisolated gyro fault can cause, rad/s: the square root of the
    /// largest fused rate variance, which carries fusion's bound on it (0 without a gyro fault).
    pub rate_bound_rps: f64,
}

impl FusionFault {
    /// The report carried by a fused sample's flags and rate variance.
    pub fn from_fused(flags: u32, rate_var: [f64; 3]) -> Self {
        let gyro_unisolated = flags & fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED != 0;
        let largest = rate_var.into_iter().fold(0.0f64, f64::max);
        // A NaN variance is no bound at all: take it as none rather than poison the covariance.
        let rate_bound_rps = if gyro_unisolated && largest.is_finite() {
            largest.sqrt()
        } else {
            0.0
        };
        Self {
            gyro_unisolated,
            accel_unisolated: flags & fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED != 0,
            rate_bound_rps,
        }
    }

    /// Any fault unisolated.
    pub fn unisolated(&self) -> bool {
        self.gyro_unisolated || self.accel_unisolated
    }
}

/// The attitude error an unisolated gyro fault may have integrated during its episode.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct UnisolatedFaultBound {
    current: FusionFault,
    /// Σ r·Δt over the episode so far, rad.
    bound_rad: f64,
}

impl UnisolatedFaultBound {
    /// Fusion's report for the sample about to be propagated.
    pub fn set(&mut self, fault: FusionFault) {
        self.current = fault;
        if !fault.gyro_unisolated {
            self.bound_rad = 0.0;
        }
    }

    /// The sample was propagated over `dt_s`: returns the variance to add to each attitude error
    /// axis (rad²), `B_new² − B_old²`, so that the total added over the episode is `B²`.
    pub fn on_step(&mut self, dt_s: f64) -> f64 {
        if !self.current.gyro_unisolated || dt_s.is_nan() || dt_s <= 0.0 {
            return 0.0;
        }
        let before = self.bound_rad;
        self.bound_rad += self.current.rate_bound_rps * dt_s;
        self.bound_rad * self.bound_rad - before * before
    }

    /// The report of the last sample.
    pub fn current(&self) -> FusionFault {
        self.current
    }

    /// The attitude error bound of the episode so far, rad.
    pub fn bound_rad(&self) -> f64 {
        self.bound_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_added_variance_sums_to_the_square_of_the_linear_bound() {
        let mut b = UnisolatedFaultBound::default();
        let fault = FusionFault::from_fused(
            fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED,
            [1e-4, 4e-4, 1e-4],
        );
        assert!((fault.rate_bound_rps - 0.02).abs() < 1e-12);
        b.set(fault);
        let added: f64 = (0..1000).map(|_| b.on_step(0.001)).sum();
        // 0.02 rad/s for 1 s: 0.02 rad, whose square is what the covariance gained.
        assert!((b.bound_rad() - 0.02).abs() < 1e-12);
        assert!((added - 0.02 * 0.02).abs() < 1e-12);
        // Isolated: the episode ends, nothing more is added.
        b.set(FusionFault::from_fused(0, [1e-4; 3]));
        assert_eq!(b.on_step(0.001), 0.0);
        assert_eq!(b.bound_rad(), 0.0);
    }

    #[test]
    fn an_accelerometer_fault_is_unisolated_without_a_rate_bound() {
        let f = FusionFault::from_fused(fused_flags::ACCEL_FAULT_DETECTED_NOT_ISOLATED, [1.0; 3]);
        assert!(f.unisolated());
        assert_eq!(f.rate_bound_rps, 0.0);
        assert!(!FusionFault::from_fused(0, [1.0; 3]).unisolated());
        let nan =
            FusionFault::from_fused(fused_flags::GYRO_FAULT_DETECTED_NOT_ISOLATED, [f64::NAN; 3]);
        assert_eq!(nan.rate_bound_rps, 0.0);
    }
}
