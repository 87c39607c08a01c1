//! Multirotor motion: the attitude follows from the rotor-drag dynamics.
//!
//! A multirotor's only forces besides gravity are the rotor thrust along body −z and the rotor
//! drag, which opposes the airspeed in the rotor plane: the specific force in body axes is
//! f_b = [−μx·v_air,x, −μy·v_air,y, −T], v_air the air-relative velocity in body axes.
//!
//! The motion is set by the schedules of [`MultirotorProfile`] (ground speed V, course χ, climb
//! rate ḣ, yaw offset δ, gust): velocity NED v = [V cos χ, V sin χ, −ḣ] and its exact derivative a,
//! yaw ψ = χ + δ. The wanted specific force s = a − g_n must equal C_nb f_b. Writing s and the
//! airspeed in the yawed frame (R_z(ψ)ᵀ), the body x and y rows give the pitch and roll in closed
//! form:
//! - body x = [cos θ, 0, −sin θ] ⟂ s + μx v_air ⇒ θ = atan2(−(s + μx v_air)_x, −(s + μx v_air)_z);
//! - body y = [sin φ sin θ, cos φ, sin φ cos θ] ⟂ u = s + μy v_air
//!   ⇒ φ = atan2(u_y, −(u_x sin θ + u_z cos θ));
//!
//! and the thrust is whatever body z needs. The truth then carries exactly this attitude, so the
//! specific force the simulator derives from it is the drag model's. The Euler-angle rates of φ
//! and θ are central differences over [`RATE_STEP_S`] (the schedules give no third derivative);
//! ψ̇ is exact.

use nalgebra::Vector3;

use super::geodesy::{GeodeticTable, Kinematics};
use super::multirotor_config::MultirotorConfig;
use super::multirotor_profile::MultirotorProfile;
use super::rotor::BladePhase;
use super::{Landmarks, TrajectoryStart, TruthState, attitude_and_body_rate, specific_force_b};
use crate::sensor_model::vibration::RotorState;
use rins_earth::STANDARD_GRAVITY;

/// Grid spacing of the precomputed latitude/longitude and blade-phase tables, s.
const TABLE_SPACING_S: f64 = 0.01;
/// Half-width of the central difference of roll and pitch, s: the error (h² times the third
/// derivative, under 10³ rad/s³ with 1 s steps) and the round-off (10⁻¹⁶/h) both stay under
/// 10⁻⁵ rad/s.
const RATE_STEP_S: f64 = 1e-4;

/// The kinematics of one instant, before the attitude.
#[derive(Debug, Clone, Copy)]
struct Motion {
    velocity_n: Vector3<f64>,
    acceleration_n: Vector3<f64>,
    wind_n: Vector3<f64>,
    yaw: f64,
    yaw_rate: f64,
    altitude_m: f64,
}

/// A multirotor trajectory.
#[derive(Debug, Clone)]
pub struct MultirotorPath {
    start: TrajectoryStart,
    config: MultirotorConfig,
    profile: MultirotorProfile,
    geodetic: GeodeticTable,
    blade_phase: BladePhase,
    /// Unit vector the gust blows towards, NED.
    gust_direction_n: Vector3<f64>,
}

impl MultirotorPath {
    /// The multirotor profile after `start.static_s` parked; its pattern repeated to last
    /// `start.uav_flight_s` when that is set.
    pub fn new(start: TrajectoryStart) -> (Self, Landmarks) {
        let config = start.multirotor;
        let profile = match start.uav_flight_s {
            Some(flight_s) => MultirotorProfile::lasting(
                start.static_s,
                config.altitude_agl_m,
                config.gust_mps,
                config.gust_rise_s,
                flight_s,
            ),
            None => MultirotorProfile::new(
                start.static_s,
                config.altitude_agl_m,
                config.gust_mps,
                config.gust_rise_s,
            ),
        };
        let (s, c) = config.gust_towards_deg.to_radians().sin_cos();
        let mut path = Self {
            start,
            config,
            geodetic: GeodeticTable::fixed(start.latitude_rad, start.longitude_rad),
            blade_phase: BladePhase::off(),
            gust_direction_n: Vector3::new(c, s, 0.0),
            profile,
        };
        let (on_s, end_s) = (path.profile.rotors_on_s, path.profile.end_s);
        path.geodetic = GeodeticTable::integrate(
            start.latitude_rad,
            start.longitude_rad,
            on_s,
            end_s,
            TABLE_SPACING_S,
            |t| {
                let m = path.motion(t);
                Kinematics {
                    v_north: m.velocity_n.x,
                    v_east: m.velocity_n.y,
                    altitude_m: m.altitude_m,
                }
            },
        );
        path.blade_phase =
            BladePhase::integrate(on_s, end_s, TABLE_SPACING_S, config.blade_pass_hz, |t| {
                path.thrust_mps2(t)
            });
        let landmarks = Landmarks {
            lift_off_s: path.profile.lift_off_s,
            touchdown_s: path.profile.touchdown_s,
            end_s,
        };
        (path, landmarks)
    }

    /// Velocity, acceleration, wind, yaw and altitude at `t`.
    fn motion(&self, t: f64) -> Motion {
        let p = &self.profile;
        let sp = p.speed.sample(t);
        let cr = p.course_rate.sample(t);
        let climb = p.climb_rate.sample(t);
        let yo = p.yaw_offset.sample(t);
        let (v, v_dot) = (sp.value, sp.rate);
        let course = self.start.heading_rad + cr.integral;
        let (s, c) = course.sin_cos();
        Motion {
            velocity_n: Vector3::new(v * c, v * s, -climb.value),
            acceleration_n: Vector3::new(
                v_dot * c - v * cr.value * s,
                v_dot * s + v * cr.value * c,
                -climb.rate,
            ),
            wind_n: self.gust_direction_n * p.gust.sample(t).value,
            yaw: course + yo.value,
            yaw_rate: cr.value + yo.rate,
            altitude_m: self.start.altitude_m + climb.integral,
        }
    }

    /// Roll and pitch that make the specific force the rotor-drag model's (see the module doc).
    fn roll_pitch(&self, m: &Motion) -> [f64; 2] {
        let s_n = m.acceleration_n - Vector3::new(0.0, 0.0, STANDARD_GRAVITY);
        let air_n = m.velocity_n - m.wind_n;
        let (sy, cy) = m.yaw.sin_cos();
        // Into the yawed frame: R_z(ψ)ᵀ.
        let yawed = |x: Vector3<f64>| Vector3::new(cy * x.x + sy * x.y, -sy * x.x + cy * x.y, x.z);
        let (s, air) = (yawed(s_n), yawed(air_n));
        let w = s + air * self.config.drag_per_s;
        let pitch = (-w.x).atan2(-w.z);
        let u = s + air * self.config.lateral_drag_per_s;
        let (sp, cp) = pitch.sin_cos();
        let roll = u.y.atan2(-(u.x * sp + u.z * cp));
        [roll, pitch]
    }

    /// Rotor thrust per unit mass at `t`, m/s² (g in hover).
    fn thrust_mps2(&self, t: f64) -> f64 {
        let m = self.motion(t);
        let [roll, pitch] = self.roll_pitch(&m);
        let (attitude, _) = attitude_and_body_rate([roll, pitch, m.yaw], [0.0; 3]);
        -specific_force_b(&attitude, &m.acceleration_n).z
    }

    /// The true state at time `t` seconds (t ≥ 0).
    pub fn sample(&self, t: f64) -> TruthState {
        let m = self.motion(t);
        let [roll, pitch] = self.roll_pitch(&m);
        let h = RATE_STEP_S;
        let ahead = self.roll_pitch(&self.motion(t + h));
        let behind = self.roll_pitch(&self.motion((t - h).max(0.0)));
        let span = t + h - (t - h).max(0.0);
        let roll_dot = (ahead[0] - behind[0]) / span;
        let pitch_dot = (ahead[1] - behind[1]) / span;
        let (attitude, angular_rate_b) =
            attitude_and_body_rate([roll, pitch, m.yaw], [roll_dot, pitch_dot, m.yaw_rate]);
        let [latitude_rad, longitude_rad] = self.geodetic.sample(t);
        let rotors_on = t >= self.profile.rotors_on_s && t < self.profile.end_s;
        let rotor = if rotors_on {
            RotorState {
                blade_phase_rad: self.blade_phase.sample(t),
                accel_amplitude_mps2: self.config.vibration_accel_mps2,
                gyro_amplitude_rps: self.config.vibration_gyro_dps.to_radians(),
            }
        } else {
            RotorState::default()
        };
        TruthState {
            time_s: t,
            attitude,
            euler_rad: [roll, pitch, m.yaw],
            angular_rate_b,
            specific_force_b: specific_force_b(&attitude, &m.acceleration_n),
            velocity_n: m.velocity_n,
            acceleration_n: m.acceleration_n,
            latitude_rad,
            longitude_rad,
            altitude_m: m.altitude_m,
            foot_load: 0.0,
            stance: !rotors_on,
            rotor,
        }
    }

    /// Wind NED at `t`, m/s.
    pub fn wind_n(&self, t: f64) -> Vector3<f64> {
        self.motion(t).wind_n
    }

    /// Blade-pass frequency at `t`, Hz (0 with the rotors stopped).
    pub fn blade_pass_hz(&self, t: f64) -> f64 {
        if t >= self.profile.rotors_on_s && t < self.profile.end_s {
            super::rotor::blade_pass_hz(self.config.blade_pass_hz, self.thrust_mps2(t))
        } else {
            0.0
        }
    }
}
