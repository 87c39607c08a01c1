//! The aided navigator's inertial core: static alignment, then the error-state EKF predicted on
//! every IMU sample, with the zero-velocity update whenever the stance detector fires.
//!
//! The pedestrian profile runs it on a foot-mounted unit; the offline evaluations and the live
//! navigator share this one code path, so what the real recordings measure is what flies.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use crate::alignment::{AlignConfig, AlignError, Alignment, StaticAligner};
use crate::ekf::{EkfNoise, ErrorStateEkf, UpdateOutcome};
use crate::mechanisation::{ImuBias, NominalState, StepOutcome, StrapdownConfig};
use crate::stance::{StanceConfig, StanceDetector};

/// Settings of the zero-velocity aiding (`[navigator.zupt]`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ZuptConfig {
    /// Apply a zero-velocity update whenever the stance detector fires (`[navigator.stance]`).
    pub enabled: bool,
    /// Velocity σ of the zero-velocity pseudo-measurement, m/s per axis.
    pub sigma_mps: f64,
    /// Innovation gate: largest accepted Mahalanobis distance of the velocity innovation.
    pub gate: f64,
}

impl Default for ZuptConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            sigma_mps: 0.01,
            gate: 1e3,
        }
    }
}

/// Settings of the inertial core.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AidedConfig {
    pub align: AlignConfig,
    pub strapdown: StrapdownConfig,
    pub noise: EkfNoise,
    pub zupt: ZuptConfig,
    pub stance: StanceConfig,
    /// Declination, rad, positive east.
    pub declination_rad: f64,
    /// Position where navigation starts: latitude, longitude (rad), altitude (m).
    pub origin: [f64; 3],
}

/// Where the navigator is in its sequence.
#[derive(Debug, Clone)]
enum Phase {
    Aligning(Box<StaticAligner>),
    Navigating(Box<ErrorStateEkf>),
}

/// What one IMU sample did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuStep {
    /// The propagation (while aligning: `None`).
    pub propagated: Option<StepOutcome>,
    /// The stance detector fired on this sample.
    pub stance: bool,
    /// The zero-velocity update, when one was attempted.
    pub zupt: Option<UpdateOutcome>,
}

/// Alignment followed by the EKF with zero-velocity updates. Allocation-free per sample once
/// aligned.
#[derive(Debug, Clone)]
pub struct AidedNavigator {
    config: AidedConfig,
    phase: Phase,
    stance: StanceDetector,
    alignment: Option<Alignment>,
    last_align_error: Option<AlignError>,
    last_time_us: Option<u64>,
}

impl AidedNavigator {
    pub fn new(config: AidedConfig) -> Self {
        let stance = StanceDetector::new(config.stance);
        Self {
            config,
            phase: Phase::Aligning(Box::new(StaticAligner::new(config.align))),
            stance,
            alignment: None,
            last_align_error: None,
            last_time_us: None,
        }
    }

    /// The filter, once aligned.
    pub fn ekf(&self) -> Option<&ErrorStateEkf> {
        match &self.phase {
            Phase::Navigating(ekf) => Some(ekf),
            Phase::Aligning(_) => None,
        }
    }

    pub fn alignment(&self) -> Option<&Alignment> {
        self.alignment.as_ref()
    }

    /// Why the last alignment window was discarded.
    pub fn last_align_error(&self) -> Option<&AlignError> {
        self.last_align_error.as_ref()
    }

    /// Feeds one IMU sample at device time `t_us`: rate rad/s, specific force m/s², body FRD, and
    /// the foot pressure when the unit has a sensor.
    pub fn on_imu(
        &mut self,
        t_us: u64,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
        pressure: Option<f64>,
    ) -> ImuStep {
        let dt_s = self
            .last_time_us
            .map_or(0.0, |last| t_us.saturating_sub(last) as f64 * 1e-6);
        self.last_time_us = Some(t_us);
        let mut step = ImuStep {
            propagated: None,
            stance: false,
            zupt: None,
        };
        match &mut self.phase {
            Phase::Aligning(aligner) => {
                aligner.push_imu(t_us, rate_rps, specific_force);
                if aligner.is_complete() {
                    match aligner.finish(self.config.declination_rad) {
                        Ok(a) => self.start(a),
                        Err(e) => {
                            self.last_align_error = Some(e);
                            aligner.reset();
                        }
                    }
                }
            }
            Phase::Navigating(ekf) => {
                let outcome = ekf.predict(rate_rps, specific_force, dt_s);
                step.propagated = Some(outcome);
                let z = self.config.zupt;
                if z.enabled {
                    // The detector sees bias-corrected rates, so a gyro bias the filter has
                    // learnt does not read as motion.
                    let b = ekf.bias();
                    let rate = Vector3::from(rate_rps) - b.gyro_rps;
                    let force = Vector3::from(specific_force) - b.accel_mps2;
                    let g = ekf.strapdown().gravity();
                    step.stance = self.stance.push(rate.into(), force.into(), pressure, g);
                    if step.stance && outcome.is_applied() {
                        step.zupt = Some(ekf.zupt(z.sigma_mps, z.gate));
                    }
                }
            }
        }
        step
    }

    fn start(&mut self, a: Alignment) {
        let [lat, lon, alt] = self.config.origin;
        let mut state = NominalState::at_rest(lat, lon, alt);
        state.attitude = a.attitude;
        let bias = ImuBias {
            gyro_rps: a.gyro_bias_rps,
            accel_mps2: Vector3::zeros(),
        };
        let ekf = ErrorStateEkf::new(state, bias, self.config.strapdown, self.config.noise);
        self.alignment = Some(a);
        self.phase = Phase::Navigating(Box::new(ekf));
    }
}
