//! Deterministic truth trajectory, sampled at device time t (seconds).
//!
//! The motion is defined by three smooth schedules — horizontal ground speed V, heading rate ψ̇ and
//! climb rate ḣ — whose values, derivatives and integrals are closed form. From them:
//! - heading ψ = ψ₀ + ∫ψ̇, altitude h = h₀ + ∫ḣ;
//! - bank φ = atan(V ψ̇ / g) (coordinated turn: no lateral specific force in a level turn),
//!   pitch θ = atan2(ḣ, V) (the body x axis follows the flight path);
//! - attitude q = R_z(ψ) R_y(θ) R_x(φ) (body FRD → NED);
//! - body rate from the exact Euler-rate relation, so it is the true derivative of q;
//! - velocity NED v = [V cos ψ, V sin ψ, −ḣ] and its exact derivative a;
//! - specific force f_b = C_nbᵀ (a − g_n), g_n = [0, 0, +g].
//!
//! The Earth is **non-rotating**: the truth body rate has no Earth-rate component and the specific
//! force has no Coriolis or centripetal terms. Gravity is the constant [`GRAVITY_MPS2`]. Latitude and
//! longitude integrate the velocity over the WGS84 ellipsoid (see [`geodesy`]); altitude is above
//! mean sea level, the origin altitude being ground level.

pub mod geodesy;
pub mod schedule;
pub mod uav_profile;

use nalgebra::{UnitQuaternion, Vector3};
use serde::Deserialize;

use crate::GRAVITY_MPS2;
use geodesy::{GeodeticTable, Kinematics};
use schedule::Schedule;
use uav_profile::UavProfile;

/// Grid spacing of the precomputed latitude/longitude table, seconds.
const GEODETIC_TABLE_SPACING_S: f64 = 0.01;

/// Which motion the simulator flies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Scenario {
    /// Parked level at the origin, fixed heading.
    #[default]
    Static,
    /// Take-off, climb, cruise circuits with banked turns, descent and landing (see [`uav_profile`]).
    Uav,
}

/// Where and how the trajectory starts.
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
    /// Time parked level before the UAV profile starts moving, s.
    pub static_s: f64,
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
}

/// A deterministic trajectory; sampling is allocation-free.
#[derive(Debug, Clone)]
pub struct Trajectory {
    start: TrajectoryStart,
    speed: Schedule,
    heading_rate: Schedule,
    climb_rate: Schedule,
    geodetic: GeodeticTable,
    lift_off_s: f64,
    touchdown_s: f64,
    end_s: f64,
}

impl Trajectory {
    /// Builds the trajectory of `scenario`. `start` should be validated first
    /// ([`crate::SimConfig::validate`]): out-of-range values do not panic but give meaningless truth
    /// (NaN for non-finite input, huge longitude rates near the poles).
    pub fn new(scenario: Scenario, start: TrajectoryStart) -> Self {
        match scenario {
            Scenario::Static => Self {
                start,
                speed: Schedule::new(0.0),
                heading_rate: Schedule::new(0.0),
                climb_rate: Schedule::new(0.0),
                geodetic: GeodeticTable::fixed(start.latitude_rad, start.longitude_rad),
                lift_off_s: f64::INFINITY,
                touchdown_s: f64::INFINITY,
                end_s: 0.0,
            },
            Scenario::Uav => {
                let profile = UavProfile::new(start.static_s);
                let mut trajectory = Self {
                    start,
                    speed: profile.speed,
                    heading_rate: profile.heading_rate,
                    climb_rate: profile.climb_rate,
                    geodetic: GeodeticTable::fixed(start.latitude_rad, start.longitude_rad),
                    lift_off_s: profile.lift_off_s,
                    touchdown_s: profile.touchdown_s,
                    end_s: profile.end_s,
                };
                let geodetic = GeodeticTable::integrate(
                    start.latitude_rad,
                    start.longitude_rad,
                    start.static_s,
                    profile.end_s,
                    GEODETIC_TABLE_SPACING_S,
                    |t| {
                        let (v, _, _, alt) = trajectory.horizontal(t);
                        Kinematics {
                            v_north: v[0],
                            v_east: v[1],
                            altitude_m: alt,
                        }
                    },
                );
                trajectory.geodetic = geodetic;
                trajectory
            }
        }
    }

    /// Time after which the vehicle stays parked (0 for the static scenario), s.
    pub fn end_s(&self) -> f64 {
        self.end_s
    }

    /// Time the vehicle leaves the ground (∞ if it never does), s.
    pub fn lift_off_s(&self) -> f64 {
        self.lift_off_s
    }

    /// Time the vehicle touches down (∞ if it never flies), s.
    pub fn touchdown_s(&self) -> f64 {
        self.touchdown_s
    }

    /// The start point and heading.
    pub fn start(&self) -> &TrajectoryStart {
        &self.start
    }

    /// Velocity NED, heading, heading rate and altitude at `t`, without the attitude.
    fn horizontal(&self, t: f64) -> ([f64; 3], f64, f64, f64) {
        let v = self.speed.sample(t).value;
        let hr = self.heading_rate.sample(t);
        let cr = self.climb_rate.sample(t);
        let psi = self.start.heading_rad + hr.integral;
        let (s, c) = psi.sin_cos();
        (
            [v * c, v * s, -cr.value],
            psi,
            hr.value,
            self.start.altitude_m + cr.integral,
        )
    }

    /// The true state at time `t` seconds (clamped to t ≥ 0).
    pub fn sample(&self, t: f64) -> TruthState {
        let t = t.max(0.0);
        let sp = self.speed.sample(t);
        let hr = self.heading_rate.sample(t);
        let cr = self.climb_rate.sample(t);
        let (v, v_dot) = (sp.value, sp.rate);
        let (psi_dot, psi_ddot) = (hr.value, hr.rate);
        let psi = self.start.heading_rad + hr.integral;
        let (h_dot, h_ddot) = (cr.value, cr.rate);

        let k = v * psi_dot / GRAVITY_MPS2;
        let roll = k.atan();
        let roll_dot = (v_dot * psi_dot + v * psi_ddot) / GRAVITY_MPS2 / (1.0 + k * k);
        let d = v * v + h_dot * h_dot;
        let (pitch, pitch_dot) = if d > 1e-12 {
            (h_dot.atan2(v), (v * h_ddot - h_dot * v_dot) / d)
        } else {
            (0.0, 0.0)
        };

        let (sr, cr_) = roll.sin_cos();
        let (sp_, cp) = pitch.sin_cos();
        let angular_rate_b = Vector3::new(
            roll_dot - psi_dot * sp_,
            pitch_dot * cr_ + psi_dot * sr * cp,
            -pitch_dot * sr + psi_dot * cr_ * cp,
        );
        let attitude = UnitQuaternion::from_euler_angles(roll, pitch, psi);

        let (spsi, cpsi) = psi.sin_cos();
        let velocity_n = Vector3::new(v * cpsi, v * spsi, -h_dot);
        let acceleration_n = Vector3::new(
            v_dot * cpsi - v * psi_dot * spsi,
            v_dot * spsi + v * psi_dot * cpsi,
            -h_ddot,
        );
        let specific_force_b = attitude
            .inverse_transform_vector(&(acceleration_n - Vector3::new(0.0, 0.0, GRAVITY_MPS2)));
        let [latitude_rad, longitude_rad] = self.geodetic.sample(t);

        TruthState {
            time_s: t,
            attitude,
            euler_rad: [roll, pitch, psi],
            angular_rate_b,
            specific_force_b,
            velocity_n,
            acceleration_n,
            latitude_rad,
            longitude_rad,
            altitude_m: self.start.altitude_m + cr.integral,
        }
    }
}
