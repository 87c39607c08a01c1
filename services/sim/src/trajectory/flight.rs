//! Vehicle motion (static and UAV scenarios) from three smooth schedules.
//!
//! The motion is defined by horizontal ground speed V, heading rate ψ̇ and climb rate ḣ, whose
//! values, derivatives and integrals are closed form (see [`super::schedule`]). From them:
//! - heading ψ = ψ₀ + ∫ψ̇, altitude h = h₀ + ∫ḣ;
//! - bank φ = atan(V ψ̇ / g) (coordinated turn: no lateral specific force in a level turn),
//!   pitch θ = atan2(ḣ, V) (the body x axis follows the flight path);
//! - velocity NED v = [V cos ψ, V sin ψ, −ḣ] and its exact derivative a.
//!
//! Latitude and longitude integrate the velocity over the WGS84 ellipsoid (see [`super::geodesy`]).

use crate::sensor_model::vibration::RotorState;
use nalgebra::Vector3;

use super::geodesy::{GeodeticTable, Kinematics};
use super::schedule::Schedule;
use super::uav_profile::UavProfile;
use super::{Landmarks, TrajectoryStart, TruthState, attitude_and_body_rate, specific_force_b};
use rins_earth::STANDARD_GRAVITY;

/// Grid spacing of the precomputed latitude/longitude table, seconds.
const GEODETIC_TABLE_SPACING_S: f64 = 0.01;

/// A vehicle trajectory built from speed, heading-rate and climb-rate schedules.
#[derive(Debug, Clone)]
pub struct FlightPath {
    start: TrajectoryStart,
    speed: Schedule,
    heading_rate: Schedule,
    climb_rate: Schedule,
    geodetic: GeodeticTable,
    /// At rest up to here (the speed schedule starts moving at this instant), s.
    rest_until_s: f64,
    /// At rest again from here on, s.
    rest_from_s: f64,
}

impl FlightPath {
    /// Parked level at the origin with the start heading, forever.
    pub fn parked(start: TrajectoryStart) -> (Self, Landmarks) {
        let path = Self {
            start,
            speed: Schedule::new(0.0),
            heading_rate: Schedule::new(0.0),
            climb_rate: Schedule::new(0.0),
            geodetic: GeodeticTable::fixed(start.latitude_rad, start.longitude_rad),
            rest_until_s: f64::INFINITY,
            rest_from_s: 0.0,
        };
        let landmarks = Landmarks {
            lift_off_s: f64::INFINITY,
            touchdown_s: f64::INFINITY,
            end_s: 0.0,
        };
        (path, landmarks)
    }

    /// The UAV profile of [`UavProfile`] after `start.static_s` seconds parked; its circuits
    /// repeated to last `start.uav_flight_s` when that is set.
    pub fn uav(start: TrajectoryStart) -> (Self, Landmarks) {
        let profile = match start.uav_flight_s {
            Some(flight_s) => UavProfile::lasting(start.static_s, flight_s),
            None => UavProfile::new(start.static_s),
        };
        let mut path = Self {
            start,
            speed: profile.speed,
            heading_rate: profile.heading_rate,
            climb_rate: profile.climb_rate,
            geodetic: GeodeticTable::fixed(start.latitude_rad, start.longitude_rad),
            rest_until_s: start.static_s,
            rest_from_s: profile.end_s,
        };
        let geodetic = GeodeticTable::integrate(
            start.latitude_rad,
            start.longitude_rad,
            start.static_s,
            profile.end_s,
            GEODETIC_TABLE_SPACING_S,
            |t| {
                let (v, alt) = path.velocity_and_altitude(t);
                Kinematics {
                    v_north: v[0],
                    v_east: v[1],
                    altitude_m: alt,
                }
            },
        );
        path.geodetic = geodetic;
        let landmarks = Landmarks {
            lift_off_s: profile.lift_off_s,
            touchdown_s: profile.touchdown_s,
            end_s: profile.end_s,
        };
        (path, landmarks)
    }

    /// Velocity NED and altitude at `t`, without the attitude (the geodetic integrand).
    fn velocity_and_altitude(&self, t: f64) -> ([f64; 3], f64) {
        let v = self.speed.sample(t).value;
        let hr = self.heading_rate.sample(t);
        let cr = self.climb_rate.sample(t);
        let (s, c) = (self.start.heading_rad + hr.integral).sin_cos();
        (
            [v * c, v * s, -cr.value],
            self.start.altitude_m + cr.integral,
        )
    }

    /// The true state at time `t` seconds (t ≥ 0).
    pub fn sample(&self, t: f64) -> TruthState {
        let sp = self.speed.sample(t);
        let hr = self.heading_rate.sample(t);
        let cr = self.climb_rate.sample(t);
        let (v, v_dot) = (sp.value, sp.rate);
        let (psi_dot, psi_ddot) = (hr.value, hr.rate);
        let psi = self.start.heading_rad + hr.integral;
        let (h_dot, h_ddot) = (cr.value, cr.rate);

        let k = v * psi_dot / STANDARD_GRAVITY;
        let roll = k.atan();
        let roll_dot = (v_dot * psi_dot + v * psi_ddot) / STANDARD_GRAVITY / (1.0 + k * k);
        let d = v * v + h_dot * h_dot;
        let (pitch, pitch_dot) = if d > 1e-12 {
            (h_dot.atan2(v), (v * h_ddot - h_dot * v_dot) / d)
        } else {
            (0.0, 0.0)
        };
        let (attitude, angular_rate_b) =
            attitude_and_body_rate([roll, pitch, psi], [roll_dot, pitch_dot, psi_dot]);

        let (spsi, cpsi) = psi.sin_cos();
        let velocity_n = Vector3::new(v * cpsi, v * spsi, -h_dot);
        let acceleration_n = Vector3::new(
            v_dot * cpsi - v * psi_dot * spsi,
            v_dot * spsi + v * psi_dot * cpsi,
            -h_ddot,
        );
        let [latitude_rad, longitude_rad] = self.geodetic.sample(t);

        TruthState {
            time_s: t,
            attitude,
            euler_rad: [roll, pitch, psi],
            angular_rate_b,
            specific_force_b: specific_force_b(&attitude, &acceleration_n),
            velocity_n,
            acceleration_n,
            latitude_rad,
            longitude_rad,
            altitude_m: self.start.altitude_m + cr.integral,
            foot_load: 0.0,
            stance: t <= self.rest_until_s || t >= self.rest_from_s,
            rotor: RotorState::default(),
        }
    }
}
