//! A foot-mounted sensor on a person walking once round the 50 m × 12.9 m rectangle of the
//! walking experiment of \[R3\] (docs/references.md), for testing zero-velocity-aided pedestrian navigation.
//!
//! The person stands still for `static_s`, then walks the four sides clockwise seen from above
//! (right turns), starting along the initial heading, and stops back at the start point, facing
//! along the last side; the foot then stays at rest forever. The foot alternates
//! - stance ([`STANCE_S`]): flat on the floor, velocity and body rate exactly zero, the pressure
//!   sensor loaded to [`STANCE_LOAD`] of full scale with [`LOAD_RAMP_S`] ramps at heel strike and
//!   toe-off;
//! - swing ([`SWING_S`]): one stride straight along the current side (cycloidal progress), lifted
//!   by up to [`LIFT_M`], pitched toe-down then toe-up by [`PITCH_AMPLITUDE_DEG`] (see [`super::gait`]).
//!
//! Each side is a whole number of strides, the nominal stride rounded so that it divides the side,
//! so the foot path is exactly the rectangle and exactly [`PATH_LENGTH_M`] long. At each corner the
//! foot yaws 90° in two halves, during the last swing before and the first swing after the corner,
//! with the cycloidal profile: it crabs by up to 45° while rounding the corner, as a pivoting foot
//! does. A single 90° swing would peak at 2·(π/2)/T ≈ 5.2 rad/s of yaw rate, the full scale of the
//! default 300 °/s gyros.
//!
//! Latitude and longitude map the local north/east offsets with the WGS84 radii of curvature at the
//! origin (a flat map): over 50 m the curvilinear mechanisation `φ̇ = v_N/(R_M(φ)+h)`,
//! `λ̇ = v_E/((R_N(φ)+h) cos φ)` differs from it by under 0.3 mm.

use crate::sensor_model::vibration::RotorState;
use std::f64::consts::FRAC_PI_4;

use nalgebra::Vector3;

use super::{
    Landmarks, TrajectoryStart, TruthState, attitude_and_body_rate, gait, specific_force_b,
};
use rins_earth::{meridian_radius, prime_vertical_radius};

/// Long side of the rectangle, m.
pub const COURSE_LENGTH_M: f64 = 50.0;
/// Short side of the rectangle, m.
pub const COURSE_WIDTH_M: f64 = 12.9;
/// Horizontal length of the foot path: the perimeter, m.
pub const PATH_LENGTH_M: f64 = 2.0 * (COURSE_LENGTH_M + COURSE_WIDTH_M);
/// Stride (one foot's displacement per gait cycle) before rounding to divide each side, m.
pub const NOMINAL_STRIDE_M: f64 = 1.3;
/// Foot flat on the floor between swings, s.
pub const STANCE_S: f64 = 0.45;
/// Foot in the air, s.
pub const SWING_S: f64 = 0.6;
/// One gait cycle of the instrumented foot, s.
pub const STRIDE_PERIOD_S: f64 = STANCE_S + SWING_S;
/// Peak foot lift at mid-swing, m.
pub const LIFT_M: f64 = 0.1;
/// Peak foot pitch, toe down after toe-off and toe up before heel strike, degrees. The pitch rate
/// then peaks at mid-swing at (16/(3√3))·(π/T)·15° ≈ 4.22 rad/s, and the body rate at ≈ 4.7 rad/s
/// (270 °/s) where a corner's yaw rate adds to it: inside the 300 °/s range of the default gyros.
pub const PITCH_AMPLITUDE_DEG: f64 = 15.0;
/// Standing still after the last step before [`WalkPath::end_s`], s.
pub const FINAL_STAND_S: f64 = 5.0;
/// Pressure-sensor load while standing, fraction of full scale.
pub const STANCE_LOAD: f64 = 0.8;
/// Duration of the load ramps at heel strike and toe-off, s.
pub const LOAD_RAMP_S: f64 = 0.05;

/// Side lengths in walking order, m.
const SIDES_M: [f64; 4] = [
    COURSE_LENGTH_M,
    COURSE_WIDTH_M,
    COURSE_LENGTH_M,
    COURSE_WIDTH_M,
];

/// Number of strides that walk a side of `side_m` metres: the nominal stride count, rounded.
pub fn strides_per_side(side_m: f64) -> usize {
    (side_m / NOMINAL_STRIDE_M).round().max(1.0) as usize
}

/// Total number of strides round the rectangle.
pub fn stride_count() -> usize {
    SIDES_M.iter().map(|&side| strides_per_side(side)).sum()
}

/// One swing, precomputed so sampling only looks it up.
#[derive(Debug, Clone, Copy)]
struct Stride {
    lift_off_s: f64,
    /// Horizontal position [north, east] from the origin at lift-off and at heel strike, m.
    from: [f64; 2],
    to: [f64; 2],
    /// Yaw at lift-off and its change over the swing, rad.
    yaw_from: f64,
    yaw_delta: f64,
}

/// Kinematics of the foot at one instant, in the local NED frame at the origin.
#[derive(Debug, Clone, Copy)]
struct FootState {
    position_n: Vector3<f64>,
    velocity_n: Vector3<f64>,
    acceleration_n: Vector3<f64>,
    euler: [f64; 3],
    euler_rate: [f64; 3],
    foot_load: f64,
    stance: bool,
}

/// The walk: the stride schedule, built once; sampling is closed form and allocation-free.
#[derive(Debug, Clone)]
pub struct WalkPath {
    start: TrajectoryStart,
    strides: Vec<Stride>,
    /// Radians of latitude per metre north and of longitude per metre east at the origin.
    rad_per_m: [f64; 2],
}

impl WalkPath {
    /// Builds the walk starting at `start` after `start.static_s` seconds standing.
    pub fn new(start: TrajectoryStart) -> Self {
        let mut strides = Vec::with_capacity(stride_count());
        let (sin, cos) = start.heading_rad.sin_cos();
        let mut direction = [cos, sin];
        let mut corner = [0.0, 0.0];
        // Yaw so far in 45° increments: integer, so the headings do not accumulate rounding.
        let mut eighth_turns = 0u32;
        for (side, &length) in SIDES_M.iter().enumerate() {
            let n = strides_per_side(length);
            let along = |j: usize| {
                // j = n gives exactly `length`, so the last stride ends exactly on the next corner.
                let d = length * (j as f64 / n as f64);
                [corner[0] + d * direction[0], corner[1] + d * direction[1]]
            };
            for j in 0..n {
                let turn = u32::from(j + 1 == n && side + 1 < SIDES_M.len())
                    + u32::from(j == 0 && side > 0);
                strides.push(Stride {
                    lift_off_s: start.static_s + strides.len() as f64 * STRIDE_PERIOD_S,
                    from: along(j),
                    to: along(j + 1),
                    yaw_from: start.heading_rad + f64::from(eighth_turns) * FRAC_PI_4,
                    yaw_delta: f64::from(turn) * FRAC_PI_4,
                });
                eighth_turns += turn;
            }
            corner = along(n);
            // Right turn: heading + 90° maps [cos ψ, sin ψ] to [−sin ψ, cos ψ] exactly.
            direction = [-direction[1], direction[0]];
        }
        let lat = start.latitude_rad;
        let rad_per_m = [
            1.0 / (meridian_radius(lat) + start.altitude_m),
            1.0 / ((prime_vertical_radius(lat) + start.altitude_m) * lat.cos()),
        ];
        Self {
            start,
            strides,
            rad_per_m,
        }
    }

    /// The foot's first lift-off, s.
    pub fn lift_off_s(&self) -> f64 {
        self.strides.first().map_or(f64::INFINITY, |s| s.lift_off_s)
    }

    /// The foot's last heel strike, s.
    pub fn touchdown_s(&self) -> f64 {
        self.strides
            .last()
            .map_or(f64::INFINITY, |s| s.lift_off_s + SWING_S)
    }

    /// End of the final stand: the foot is at rest from the last heel strike on, s.
    pub fn end_s(&self) -> f64 {
        self.touchdown_s() + FINAL_STAND_S
    }

    /// First lift-off, last heel strike and end of the final stand.
    pub fn landmarks(&self) -> Landmarks {
        Landmarks {
            lift_off_s: self.lift_off_s(),
            touchdown_s: self.touchdown_s(),
            end_s: self.end_s(),
        }
    }

    /// Position NED of the sensor relative to the origin at `t` (down is minus the lift), m.
    pub fn position_n(&self, t: f64) -> Vector3<f64> {
        self.state(t).position_n
    }

    /// The true state at time `t` seconds (t ≥ 0).
    pub fn sample(&self, t: f64) -> TruthState {
        let f = self.state(t);
        let (attitude, angular_rate_b) = attitude_and_body_rate(f.euler, f.euler_rate);
        TruthState {
            time_s: t,
            attitude,
            euler_rad: f.euler,
            angular_rate_b,
            specific_force_b: specific_force_b(&attitude, &f.acceleration_n),
            velocity_n: f.velocity_n,
            acceleration_n: f.acceleration_n,
            latitude_rad: self.start.latitude_rad + f.position_n.x * self.rad_per_m[0],
            longitude_rad: self.start.longitude_rad + f.position_n.y * self.rad_per_m[1],
            altitude_m: self.start.altitude_m - f.position_n.z,
            foot_load: f.foot_load,
            stance: f.stance,
            rotor: RotorState::default(),
        }
    }

    fn state(&self, t: f64) -> FootState {
        let next = self.strides.partition_point(|s| s.lift_off_s <= t);
        let next_lift_off_s = self
            .strides
            .get(next)
            .map_or(f64::INFINITY, |s| s.lift_off_s);
        let Some(stride) = next.checked_sub(1).and_then(|i| self.strides.get(i)) else {
            return rest(
                [0.0, 0.0],
                self.start.heading_rad,
                f64::NEG_INFINITY,
                next_lift_off_s,
                t,
            );
        };
        let touchdown_s = stride.lift_off_s + SWING_S;
        if t >= touchdown_s {
            return rest(
                stride.to,
                stride.yaw_from + stride.yaw_delta,
                touchdown_s,
                next_lift_off_s,
                t,
            );
        }
        swing(stride, (t - stride.lift_off_s) / SWING_S)
    }
}

/// Foot flat at `position` with yaw `yaw`, between the heel strike at `touchdown_s` and the
/// toe-off at `lift_off_s` (either may be infinite).
fn rest(position: [f64; 2], yaw: f64, touchdown_s: f64, lift_off_s: f64, t: f64) -> FootState {
    let load = STANCE_LOAD
        * gait::load_ramp(t - touchdown_s, LOAD_RAMP_S)
        * gait::load_ramp(lift_off_s - t, LOAD_RAMP_S);
    FootState {
        position_n: Vector3::new(position[0], position[1], 0.0),
        velocity_n: Vector3::zeros(),
        acceleration_n: Vector3::zeros(),
        euler: [0.0, 0.0, yaw],
        euler_rate: [0.0; 3],
        foot_load: load,
        stance: true,
    }
}

/// The foot in the air at swing phase `u` ∈ [0, 1) of `stride`.
fn swing(stride: &Stride, u: f64) -> FootState {
    let progress = gait::progress(u, SWING_S);
    let lift = gait::lift(u, SWING_S).scaled(LIFT_M);
    let pitch = gait::pitch(u, SWING_S).scaled(PITCH_AMPLITUDE_DEG.to_radians());
    let yaw = progress.scaled(stride.yaw_delta);
    let step = [stride.to[0] - stride.from[0], stride.to[1] - stride.from[1]];
    FootState {
        position_n: Vector3::new(
            stride.from[0] + step[0] * progress.value,
            stride.from[1] + step[1] * progress.value,
            -lift.value,
        ),
        velocity_n: Vector3::new(step[0] * progress.rate, step[1] * progress.rate, -lift.rate),
        acceleration_n: Vector3::new(
            step[0] * progress.accel,
            step[1] * progress.accel,
            -lift.accel,
        ),
        euler: [0.0, pitch.value, stride.yaw_from + yaw.value],
        euler_rate: [0.0, pitch.rate, yaw.rate],
        foot_load: 0.0,
        stance: false,
    }
}
