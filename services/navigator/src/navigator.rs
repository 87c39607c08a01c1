//! The navigator: static alignment, then strapdown propagation with the baro height blend.
//!
//! Sequence. IMU samples fill the alignment window; when it spans `align_s` of device time the window is
//! checked and either gives the initial attitude and gyro bias or is discarded and restarted (the reason
//! is kept in [`Navigator::last_align_error`]). The sample that completes a good window is the reference
//! epoch of the navigation solution and the first one with an output; each later sample propagates by the
//! device-time difference to the previous one. A difference that is not positive or exceeds `max_dt_s`
//! is a device-time glitch: the sample is not integrated and the epoch jumps to it.
//!
//! Initial state: position from the configuration, altitude from the first valid baro reading if one
//! arrived (else the configured altitude, and the first valid reading after alignment then sets it),
//! velocity zero. The component of the mean specific force along itself in excess of model gravity is
//! taken as accelerometer bias, so that the static window integrates to exactly zero velocity: at rest
//! only this component of the accelerometer bias is observable, the rest is absorbed in roll and pitch.
//!
//! Magnetometer samples are used only in the alignment window in this version.

use ipc_types::{NavMode, NavState, aiding};
use nalgebra::Vector3;

use crate::alignment::{AlignError, Alignment, StaticAligner};
use crate::attitude::quaternion_to_array;
use crate::baro_blend::{BaroBlend, BaroOutcome};
use crate::config::{ConfigError, NavigatorConfig};
use crate::mechanisation::{ImuBias, NominalState, StepOutcome, Strapdown};

/// One navigation solution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NavOutput {
    /// Device time of the solution, µs.
    pub device_time_us: u64,
    /// Body (FRD) → NED attitude, Hamilton, `[w, x, y, z]`.
    pub quaternion: [f64; 4],
    /// Velocity NED, m/s.
    pub velocity_ned: [f64; 3],
    /// Latitude, rad.
    pub lat: f64,
    /// Longitude, rad.
    pub lon: f64,
    /// Altitude, m.
    pub alt: f64,
    /// Aligning or navigating.
    pub mode: NavMode,
    /// A valid baro reading was blended within the aiding timeout.
    pub aiding_baro: bool,
    /// The heading was initialised from the magnetometer.
    pub aiding_mag: bool,
}

impl NavOutput {
    /// Copies the solution into an IPC payload; leaves its header and covariance untouched.
    pub fn write_nav_state(&self, out: &mut NavState) {
        out.mode = self.mode as u8;
        out.aiding = if self.aiding_baro { aiding::BARO } else { 0 }
            | if self.aiding_mag { aiding::MAG } else { 0 };
        out.quaternion = self.quaternion;
        out.velocity_ned_mps = self.velocity_ned;
        out.latitude_rad = self.lat;
        out.longitude_rad = self.lon;
        out.altitude_m = self.alt;
    }
}

/// Strapdown navigator with static alignment and baro height blend. Allocation-free per sample.
#[derive(Debug, Clone)]
pub struct Navigator {
    config: NavigatorConfig,
    declination_rad: f64,
    aiding_timeout_us: u64,
    aligner: StaticAligner,
    strapdown: Strapdown,
    blend: BaroBlend,
    mode: NavMode,
    alignment: Option<Alignment>,
    last_align_error: Option<AlignError>,
    /// Device time of the navigation state (of the last IMU sample while aligning), µs.
    state_time_us: u64,
    /// First valid baro height seen, m.
    baro_initial_altitude: Option<f64>,
    last_baro_used_us: Option<u64>,
    rejected_imu_samples: u64,
}

impl Navigator {
    /// A navigator waiting for its alignment window. Fails when the configuration is out of range.
    pub fn new(config: NavigatorConfig) -> Result<Self, ConfigError> {
        config.validate()?;
        let rest = Self::rest_state(&config);
        Ok(Self {
            declination_rad: config.declination_deg.to_radians(),
            aiding_timeout_us: (config.aiding_timeout_s * 1e6).round() as u64,
            aligner: StaticAligner::new(config.align_config()),
            strapdown: Strapdown::new(rest, ImuBias::default(), config.strapdown_config()),
            blend: BaroBlend::new(config.baro_blend_config()),
            mode: NavMode::Aligning,
            alignment: None,
            last_align_error: None,
            state_time_us: 0,
            baro_initial_altitude: None,
            last_baro_used_us: None,
            rejected_imu_samples: 0,
            config,
        })
    }

    fn rest_state(config: &NavigatorConfig) -> NominalState {
        NominalState::at_rest(
            config.initial_latitude_deg.to_radians(),
            config.initial_longitude_deg.to_radians(),
            config.initial_altitude_m,
        )
    }

    /// Drops the solution and starts a new alignment window.
    pub fn restart_alignment(&mut self) {
        let config = self.config.clone();
        if let Ok(fresh) = Self::new(config) {
            *self = fresh;
        }
    }

    /// The configuration in use.
    pub fn config(&self) -> &NavigatorConfig {
        &self.config
    }

    /// Aligning or navigating.
    pub fn mode(&self) -> NavMode {
        self.mode
    }

    /// The alignment the solution started from.
    pub fn alignment(&self) -> Option<&Alignment> {
        self.alignment.as_ref()
    }

    /// Why the last alignment window was discarded, until an alignment succeeds.
    pub fn last_align_error(&self) -> Option<&AlignError> {
        self.last_align_error.as_ref()
    }

    /// The strapdown integrator (nominal state and biases).
    pub fn strapdown(&self) -> &Strapdown {
        &self.strapdown
    }

    /// IMU samples not integrated because of a device-time glitch or non-finite values.
    pub fn rejected_imu_samples(&self) -> u64 {
        self.rejected_imu_samples
    }

    /// One fused IMU sample: body rate (rad/s) and specific force (m/s²), FRD, at device time (µs).
    /// `None` while aligning; a solution from the sample that completes the alignment on.
    pub fn on_imu(
        &mut self,
        device_time_us: u64,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
    ) -> Option<NavOutput> {
        if self.mode == NavMode::Aligning {
            self.state_time_us = device_time_us;
            self.aligner
                .push_imu(device_time_us, rate_rps, specific_force);
            if !self.aligner.is_complete() {
                return None;
            }
            match self.aligner.finish(self.declination_rad) {
                Ok(alignment) => self.start_navigation(alignment, device_time_us),
                Err(error) => {
                    self.last_align_error = Some(error);
                    self.aligner.reset();
                    return None;
                }
            }
            return Some(self.output());
        }

        let dt_s = if device_time_us > self.state_time_us {
            (device_time_us - self.state_time_us) as f64 * 1e-6
        } else {
            0.0
        };
        match self.strapdown.propagate(rate_rps, specific_force, dt_s) {
            StepOutcome::Applied => self.state_time_us = device_time_us,
            StepOutcome::InvalidDt => {
                self.state_time_us = device_time_us;
                self.rejected_imu_samples += 1;
            }
            // The epoch stays: the next good sample integrates across this one.
            StepOutcome::NonFiniteInput => self.rejected_imu_samples += 1,
        }
        Some(self.output())
    }

    fn start_navigation(&mut self, alignment: Alignment, device_time_us: u64) {
        let mut state = Self::rest_state(&self.config);
        state.attitude = alignment.attitude;
        if let Some(alt) = self.baro_initial_altitude {
            state.alt = alt;
        }
        let mut strapdown =
            Strapdown::new(state, ImuBias::default(), self.config.strapdown_config());
        let f = alignment.mean_specific_force_mps2;
        let magnitude = f.norm();
        let accel_bias = if magnitude > 0.0 {
            f * (1.0 - strapdown.gravity() / magnitude)
        } else {
            Vector3::zeros()
        };
        *strapdown.bias_mut() = ImuBias {
            gyro_rps: alignment.gyro_bias_rps,
            accel_mps2: accel_bias,
        };
        self.strapdown = strapdown;
        self.blend.restart();
        self.state_time_us = device_time_us;
        self.alignment = Some(alignment);
        self.last_align_error = None;
        self.mode = NavMode::Navigating;
    }

    /// One magnetometer sample, µT, body FRD. Used for the alignment heading.
    pub fn on_mag(&mut self, device_time_us: u64, field_ut: [f64; 3]) {
        if self.mode == NavMode::Aligning {
            self.aligner.push_mag(device_time_us, field_ut);
        }
    }

    /// One barometric height (m, positive up) at device time (µs); ignored unless `valid`.
    pub fn on_baro(&mut self, device_time_us: u64, height_m: f64, valid: bool) {
        if !valid || !height_m.is_finite() {
            return;
        }
        if self.baro_initial_altitude.is_none() {
            self.baro_initial_altitude = Some(height_m);
            if self.mode != NavMode::Aligning {
                // No baro at alignment: take the height directly rather than through a slow transient.
                self.strapdown.state_mut().alt = height_m;
                self.blend.restart();
            }
        }
        if self.mode == NavMode::Aligning {
            return;
        }
        let outcome = self.blend.apply(
            self.strapdown.state_mut(),
            self.state_time_us,
            device_time_us,
            height_m,
            valid,
        );
        if matches!(outcome, BaroOutcome::Applied { .. } | BaroOutcome::Started) {
            self.last_baro_used_us = Some(device_time_us);
        }
    }

    /// The current solution (a level, at-rest placeholder at the configured position while aligning).
    pub fn output(&self) -> NavOutput {
        let s = self.strapdown.state();
        let navigating = self.mode != NavMode::Aligning;
        let aiding_baro = navigating
            && self
                .last_baro_used_us
                .is_some_and(|t| self.state_time_us <= t.saturating_add(self.aiding_timeout_us));
        NavOutput {
            device_time_us: self.state_time_us,
            quaternion: quaternion_to_array(&s.attitude),
            velocity_ned: s.velocity_ned.into(),
            lat: s.lat,
            lon: s.lon,
            alt: s.alt,
            mode: self.mode,
            aiding_baro,
            aiding_mag: navigating && self.alignment.is_some_and(|a| a.heading_aided),
        }
    }
}

/// Whether a fused IMU sample (its `FusedImu::flags`) may drive the navigator: both solutions valid,
/// and fusion no longer measuring per-channel gyro biases — the rate before that correction carries
/// the biases the alignment window would otherwise average into its own estimate.
pub fn fused_sample_usable(flags: u32) -> bool {
    use ipc_types::fused_flags;
    flags
        & (fused_flags::GYRO_INSUFFICIENT
            | fused_flags::ACCEL_INSUFFICIENT
            | fused_flags::GYRO_REST_BIAS_PENDING)
        == 0
}
