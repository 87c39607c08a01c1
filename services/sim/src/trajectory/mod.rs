//! Deterministic truth trajectory, sampled at device time t (seconds).
//!
//! Three motion generators share the conventions below: a vehicle moved by smooth schedules (the
//! static and UAV scenarios, [`flight`]), a foot-mounted sensor on a walking person ([`walk`]) and
//! the block turned on the spot through every orientation ([`calibration`]); and a quadrotor whose
//! attitude follows from its rotor-drag dynamics ([`multirotor`]).
//! Each gives Euler angles and their rates, velocity and acceleration in closed form; then
//! - attitude q = R_z(ψ) R_y(θ) R_x(φ) (body FRD → NED);
//! - body rate from the exact Euler-rate relation, so it is the true derivative of q;
//! - specific force f_b = C_nbᵀ (a − g_n), g_n = [0, 0, +g].
//!
//! The Earth is **non-rotating**: the truth body rate has no Earth-rate component and the specific
//! force has no Coriolis or centripetal terms. Gravity is the constant [`STANDARD_GRAVITY`]. Altitude is
//! above mean sea level, the origin altitude being ground level.

pub mod calibration;
pub mod flight;
pub mod gait;
pub mod geodesy;
pub mod multirotor;
pub mod multirotor_config;
pub mod multirotor_profile;
pub mod rotor;
pub mod schedule;
pub mod uav_profile;
pub mod walk;

use nalgebra::{UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

use calibration::CalibrationPath;
use flight::FlightPath;
use multirotor::MultirotorPath;
use multirotor_config::MultirotorConfig;
use rins_earth::STANDARD_GRAVITY;
use walk::WalkPath;

use crate::sensor_model::vibration::RotorState;

/// Which motion the simulator produces.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Scenario {
    /// Parked level at the origin, fixed heading.
    Static,
    /// Take-off, climb, cruise circuits with banked turns, descent and landing (see [`uav_profile`]).
    /// The default: something moves as soon as the pipeline runs.
    #[default]
    Uav,
    /// A foot-mounted sensor walked once round a 50 m × 12.9 m rectangle (see [`walk`]).
    Walk,
    /// Turned on the spot through every orientation, over and over, with the magnetometer's hard
    /// and soft iron of `[sim.calibration]`: what `rins calibrate mag` needs (see [`calibration`]).
    Calibrate,
    /// A quadrotor: take-off, hover, a repeated pattern of sharp turns, speed changes and a wind
    /// gust, landing; its attitude follows from the rotor-drag dynamics of `[sim.multirotor]`
    /// and its rotors shake the block (see [`multirotor`]).
    Multirotor,
}

/// Where and how the trajectory starts, and how long the UAV flies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryStart {
    /// Geodetic latitude of the origin, rad.
    pub latitude_rad: f64,
    /// Longitude of the origin, rad.
    pub longitude_rad: f64,
    /// Ground altitude at the origin above mean sea level, m.
    pub altitude_m: f64,
    /// Initial heading (yaw from north, clockwise), rad.
    pub heading_rad: f64,
    /// Time at rest, level, before the UAV profile or the walk starts moving, s.
    pub static_s: f64,
    /// UAV and multirotor scenarios: the flight (parking included) lasts up to this long, its
    /// circuits (patterns) repeated as many times as fit; `None`: one pair of circuits (one
    /// pattern). Ignored by the other scenarios.
    pub uav_flight_s: Option<f64>,
    /// Calibrate scenario: time of one full yaw turn, s (> 0). Ignored by the other scenarios.
    pub calibration_sweep_s: f64,
    /// Multirotor scenario: the airframe, its gust and its vibration. Ignored by the others.
    pub multirotor: MultirotorConfig,
}

/// The true state at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthState {
    /// Sample time, s.
    pub time_s: f64,
    /// Attitude, body (FRD) → NED.
    pub attitude: UnitQuaternion<f64>,
    /// [roll, pitch, yaw] of the attitude, rad (yaw not wrapped).
    pub euler_rad: [f64; 3],
    /// Body angular rate w.r.t. the (non-rotating) navigation frame, FRD, rad/s.
    pub angular_rate_b: Vector3<f64>,
    /// Specific force in the body frame, m/s².
    pub specific_force_b: Vector3<f64>,
    /// Velocity NED, m/s.
    pub velocity_n: Vector3<f64>,
    /// Acceleration NED (dv/dt), m/s².
    pub acceleration_n: Vector3<f64>,
    /// Geodetic latitude, rad.
    pub latitude_rad: f64,
    /// Longitude, rad.
    pub longitude_rad: f64,
    /// Altitude above mean sea level, m.
    pub altitude_m: f64,
    /// Load on the foot-pressure sensor, 0 (none) ..= 1 (full scale); 0 unless walking.
    pub foot_load: f64,
    /// The sensor is at rest — velocity and body rate exactly zero: the foot flat on the floor
    /// between steps in the walk, parked before and after the motion in the other scenarios. This
    /// is what a zero-velocity detector should find.
    pub stance: bool,
    /// The rotors' vibration of the block (zero amplitude unless a multirotor's rotors turn).
    pub rotor: RotorState,
}

/// Landmark times of a motion, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landmarks {
    /// The vehicle leaves the ground; in the walk, the foot's first lift-off (∞ if never).
    pub lift_off_s: f64,
    /// The vehicle touches down; in the walk, the foot's last heel strike (∞ if it never flies).
    pub touchdown_s: f64,
    /// At rest for good from here on (0 if it never moves, ∞ if it never stops).
    pub end_s: f64,
}

/// The motion generator behind a [`Trajectory`].
#[derive(Debug, Clone)]
enum Motion {
    Flight(FlightPath),
    Walk(WalkPath),
    Calibration(CalibrationPath),
    Multirotor(Box<MultirotorPath>),
}

/// A deterministic trajectory; sampling is allocation-free.
#[derive(Debug, Clone)]
pub struct Trajectory {
    start: TrajectoryStart,
    motion: Motion,
    landmarks: Landmarks,
}

impl Trajectory {
    /// Builds the trajectory of `scenario`. `start` should be validated first
    /// ([`crate::SimConfig::validate`]): out-of-range values do not panic but give meaningless truth
    /// (NaN for non-finite input, huge longitude rates near the poles).
    pub fn new(scenario: Scenario, start: TrajectoryStart) -> Self {
        let (motion, landmarks) = match scenario {
            Scenario::Static => {
                let (path, landmarks) = FlightPath::parked(start);
                (Motion::Flight(path), landmarks)
            }
            Scenario::Uav => {
                let (path, landmarks) = FlightPath::uav(start);
                (Motion::Flight(path), landmarks)
            }
            Scenario::Walk => {
                let path = WalkPath::new(start);
                let landmarks = path.landmarks();
                (Motion::Walk(path), landmarks)
            }
            Scenario::Calibrate => {
                let (path, landmarks) = CalibrationPath::new(start, start.calibration_sweep_s);
                (Motion::Calibration(path), landmarks)
            }
            Scenario::Multirotor => {
                let (path, landmarks) = MultirotorPath::new(start);
                (Motion::Multirotor(Box::new(path)), landmarks)
            }
        };
        Self {
            start,
            motion,
            landmarks,
        }
    }

    /// Time after which the vehicle (or the walker) stays at rest for good (0 for the static
    /// scenario, ∞ for the calibrate scenario, which never stops), s.
    pub fn end_s(&self) -> f64 {
        self.landmarks.end_s
    }

    /// Time the vehicle leaves the ground — in the walk, the foot's first lift-off (∞ if it never
    /// does), s.
    pub fn lift_off_s(&self) -> f64 {
        self.landmarks.lift_off_s
    }

    /// Time the vehicle touches down — in the walk, the foot's last heel strike (∞ if it never
    /// flies), s.
    pub fn touchdown_s(&self) -> f64 {
        self.landmarks.touchdown_s
    }

    /// The start point and heading.
    pub fn start(&self) -> &TrajectoryStart {
        &self.start
    }

    /// Wind NED at `t`, m/s: the multirotor's gust, calm in the other scenarios.
    pub fn wind_n(&self, t: f64) -> Vector3<f64> {
        match &self.motion {
            Motion::Multirotor(path) => path.wind_n(t.max(0.0)),
            _ => Vector3::zeros(),
        }
    }

    /// Blade-pass frequency of the rotors at `t`, Hz: 0 unless a multirotor's rotors turn.
    pub fn blade_pass_hz(&self, t: f64) -> f64 {
        match &self.motion {
            Motion::Multirotor(path) => path.blade_pass_hz(t.max(0.0)),
            _ => 0.0,
        }
    }

    /// The true state at time `t` seconds (clamped to t ≥ 0).
    pub fn sample(&self, t: f64) -> TruthState {
        let t = t.max(0.0);
        match &self.motion {
            Motion::Flight(path) => path.sample(t),
            Motion::Walk(path) => path.sample(t),
            Motion::Calibration(path) => path.sample(t),
            Motion::Multirotor(path) => path.sample(t),
        }
    }
}

/// Attitude R_z(ψ) R_y(θ) R_x(φ) of `[φ, θ, ψ]` and the body rate that is its exact derivative,
/// given the Euler-angle rates: ω = [φ̇ − ψ̇ sin θ, θ̇ cos φ + ψ̇ sin φ cos θ, −θ̇ sin φ + ψ̇ cos φ cos θ].
fn attitude_and_body_rate(
    euler: [f64; 3],
    euler_rate: [f64; 3],
) -> (UnitQuaternion<f64>, Vector3<f64>) {
    let [roll, pitch, yaw] = euler;
    let [roll_dot, pitch_dot, yaw_dot] = euler_rate;
    let (sr, cr) = roll.sin_cos();
    let (sp, cp) = pitch.sin_cos();
    let angular_rate_b = Vector3::new(
        roll_dot - yaw_dot * sp,
        pitch_dot * cr + yaw_dot * sr * cp,
        -pitch_dot * sr + yaw_dot * cr * cp,
    );
    (
        UnitQuaternion::from_euler_angles(roll, pitch, yaw),
        angular_rate_b,
    )
}

/// Specific force in the body frame, f_b = C_nbᵀ (a − g_n), for acceleration `a` NED.
fn specific_force_b(attitude: &UnitQuaternion<f64>, acceleration_n: &Vector3<f64>) -> Vector3<f64> {
    attitude.inverse_transform_vector(&(acceleration_n - Vector3::new(0.0, 0.0, STANDARD_GRAVITY)))
}
