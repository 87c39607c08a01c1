//! Quaternion strapdown mechanisation: the nominal attitude, velocity and position.
//!
//! Model (docs/design.md §6.3), non-rotating Earth in this version: no Earth rate in the attitude update, no
//! Coriolis or transport-rate terms in the velocity update. Over a short flight the Earth rate
//! (7.3e-5 rad/s) is absorbed into the gyro bias measured at alignment.
//!
//! * Attitude: `q ← q ⊗ exp(½ φ)` with the exact rotation-vector exponential. Each rate sample is taken as
//!   the mean rate over its interval, so `α_k = ω_k Δt` is the angle increment; with coning compensation
//!   on, `φ = α_k + (1/12) α_{k−1} × α_k`, the second-order correction of a rate that varies linearly
//!   across two intervals (Savage, Strapdown Analytics). The correction vanishes for a fixed axis.
//! * Velocity: `v̇ = C(q) f + gⁿ`, `gⁿ = [0, 0, +γ(φ, h)]` with WGS84 normal gravity
//!   ([`normal_gravity`]) evaluated at the position at the start of the step. The specific force is
//!   rotated with the attitude at the middle of the interval, `q ⊗ exp(¼ φ)`; no sculling term.
//! * Position: `φ̇ = v_N/(R_N+h)`, `λ̇ = v_E/((R_E+h) cos φ)`, `ḣ = −v_D`, with `R_N` the meridian and `R_E`
//!   the prime-vertical WGS84 radii, trapezoidal velocity and radii at the mid-step latitude and height.
//!   Latitude is clamped to ±90° (trajectories over a pole are out of scope), longitude wraps to (−π, π].

use nalgebra::{UnitQuaternion, Vector3};

use crate::attitude::{rotation_vector_to_quaternion, wrap_pi};
use rins_earth::{meridian_radius, normal_gravity, prime_vertical_radius};

pub use crate::attitude::{euler_from_quaternion, quaternion_from_euler};

/// Smallest `cos φ` used for the longitude rate, so that the pole gives a large but finite rate.
const MIN_COS_LATITUDE: f64 = 1e-6;

/// Settings of the strapdown integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StrapdownConfig {
    /// Largest accepted step, s; a longer gap is a device-time glitch and the step is skipped.
    pub max_dt_s: f64,
    /// Apply the two-sample coning correction.
    pub coning_correction: bool,
}

impl Default for StrapdownConfig {
    fn default() -> Self {
        Self {
            max_dt_s: 0.1,
            coning_correction: true,
        }
    }
}

/// Sensor biases subtracted from every sample before integration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ImuBias {
    /// Gyro bias, body FRD, rad/s.
    pub gyro_rps: Vector3<f64>,
    /// Accelerometer bias, body FRD, m/s².
    pub accel_mps2: Vector3<f64>,
}

/// The nominal navigation state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NominalState {
    /// Body (FRD) → NED rotation.
    pub attitude: UnitQuaternion<f64>,
    /// Velocity in NED, m/s.
    pub velocity_ned: Vector3<f64>,
    /// Geodetic latitude, rad.
    pub lat: f64,
    /// Longitude, rad.
    pub lon: f64,
    /// Height, m (positive up).
    pub alt: f64,
}

impl NominalState {
    /// Level, at rest, at the given position.
    pub fn at_rest(lat: f64, lon: f64, alt: f64) -> Self {
        Self {
            attitude: UnitQuaternion::identity(),
            velocity_ned: Vector3::zeros(),
            lat,
            lon,
            alt,
        }
    }

    /// `[roll, pitch, yaw]`, rad, ZYX aerospace.
    pub fn euler(&self) -> [f64; 3] {
        euler_from_quaternion(&self.attitude)
    }
}

/// Why a step was or was not applied.
#[must_use]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepOutcome {
    /// The state was propagated.
    Applied,
    /// `dt` was not finite, not positive or above `max_dt_s`; the state is unchanged.
    InvalidDt,
    /// A rate or specific-force component was not finite; the state is unchanged.
    NonFiniteInput,
}

impl StepOutcome {
    /// True when the state was propagated.
    pub fn is_applied(self) -> bool {
        self == StepOutcome::Applied
    }
}

/// Strapdown integrator holding the nominal state and the biases it subtracts.
#[derive(Debug, Clone, PartialEq)]
pub struct Strapdown {
    state: NominalState,
    bias: ImuBias,
    config: StrapdownConfig,
    /// Angle increment of the previous accepted step, for the coning term.
    previous_increment: Option<Vector3<f64>>,
    /// Specific force rotated to NED in the last step, m/s².
    specific_force_ned: Vector3<f64>,
}

impl Strapdown {
    /// Starts from `state` with `bias`.
    pub fn new(state: NominalState, bias: ImuBias, config: StrapdownConfig) -> Self {
        Self {
            state,
            bias,
            config,
            previous_increment: None,
            specific_force_ned: Vector3::zeros(),
        }
    }

    /// The nominal state.
    pub fn state(&self) -> &NominalState {
        &self.state
    }

    /// The nominal state, for corrections by an aiding filter.
    pub fn state_mut(&mut self) -> &mut NominalState {
        &mut self.state
    }

    /// The biases subtracted from each sample.
    pub fn bias(&self) -> &ImuBias {
        &self.bias
    }

    /// The biases, for corrections by an aiding filter.
    pub fn bias_mut(&mut self) -> &mut ImuBias {
        &mut self.bias
    }

    /// The settings.
    pub fn config(&self) -> &StrapdownConfig {
        &self.config
    }

    /// Bias-corrected specific force of the last applied step, rotated to NED, m/s² (`fⁿ` of the error model).
    pub fn specific_force_ned(&self) -> Vector3<f64> {
        self.specific_force_ned
    }

    /// Gravity magnitude the next step will use (at the current position), m/s².
    pub fn gravity(&self) -> f64 {
        normal_gravity(self.state.lat, self.state.alt)
    }

    /// Forgets the previous angle increment, e.g. after a gap in the samples.
    pub fn reset_coning_history(&mut self) {
        self.previous_increment = None;
    }

    /// Propagates by one IMU sample: body rate (rad/s) and specific force (m/s²), FRD, each the mean over
    /// the `dt_s` interval ending now. Biases are subtracted here. Allocation-free.
    pub fn propagate(
        &mut self,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
        dt_s: f64,
    ) -> StepOutcome {
        // Written so that NaN fails the test.
        if !(dt_s > 0.0 && dt_s <= self.config.max_dt_s) {
            self.previous_increment = None;
            return StepOutcome::InvalidDt;
        }
        if !rate_rps
            .iter()
            .chain(specific_force.iter())
            .all(|x| x.is_finite())
        {
            self.previous_increment = None;
            return StepOutcome::NonFiniteInput;
        }
        let rate = Vector3::from(rate_rps) - self.bias.gyro_rps;
        let force = Vector3::from(specific_force) - self.bias.accel_mps2;

        let increment = rate * dt_s;
        let mut rotation = increment;
        if self.config.coning_correction
            && let Some(previous) = self.previous_increment
        {
            rotation += previous.cross(&increment) / 12.0;
        }
        self.previous_increment = Some(increment);

        let s = &mut self.state;
        let q_start = s.attitude;
        let q_mid = q_start * rotation_vector_to_quaternion(&(rotation * 0.5));
        let mut q_end = q_start * rotation_vector_to_quaternion(&rotation);
        q_end.renormalize();

        let gravity = normal_gravity(s.lat, s.alt);
        let force_ned = q_mid * force;
        let v_start = s.velocity_ned;
        let v_end = v_start + (force_ned + Vector3::new(0.0, 0.0, gravity)) * dt_s;
        let v_mean = (v_start + v_end) * 0.5;

        let alt_end = s.alt - v_mean.z * dt_s;
        let alt_mid = 0.5 * (s.alt + alt_end);
        // Latitude at mid-step from a first-order predictor, then the radii there.
        let lat_mid = s.lat + 0.5 * v_mean.x * dt_s / (meridian_radius(s.lat) + alt_mid);
        let dlat = v_mean.x * dt_s / (meridian_radius(lat_mid) + alt_mid);
        let cos_lat = lat_mid.cos().max(MIN_COS_LATITUDE);
        let dlon = v_mean.y * dt_s / ((prime_vertical_radius(lat_mid) + alt_mid) * cos_lat);

        s.attitude = q_end;
        s.velocity_ned = v_end;
        s.lat = (s.lat + dlat).clamp(-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2);
        s.lon = wrap_pi(s.lon + dlon);
        s.alt = alt_end;
        self.specific_force_ned = force_ned;
        StepOutcome::Applied
    }
}
