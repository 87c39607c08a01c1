//! The `calibrate` scenario: the sensor block turned on the spot through every orientation, so a
//! magnetometer calibration (`rins calibrate mag`) can be shown without hardware.
//!
//! After `static_s` at rest, level (the window alignment needs), the block makes a full yaw turn at
//! each of eight tilts — rolled 0°, 60°, …, 300° about its x axis, then pitched +75° and −75° —
//! and returns level; the cycle repeats for as long as the simulator runs. A level turn sweeps the
//! body-frame field round a cone about the body z axis (half angle 90° − dip); the tilts point
//! that cone's axis round the body y–z circle and near ±x, so the readings cover the whole sphere
//! of field directions within one cycle.
//!
//! Roll and pitch follow smooth steps of angle (see [`super::schedule`]); the yaw follows smooth
//! steps of *rate*, so each turn runs at a constant rate between short ramps instead of peaking at
//! twice the mean. The block rotates about its own centre and does not move: the specific force is
//! gravity alone.

use crate::sensor_model::vibration::RotorState;
use std::f64::consts::{PI, TAU};

use nalgebra::Vector3;

use super::schedule::Schedule;
use super::{Landmarks, TrajectoryStart, TruthState, attitude_and_body_rate, specific_force_b};

/// Tilts (roll, pitch), degrees, at which the block makes one full yaw turn, in order. Roll keeps
/// growing (300° → 360° is one more 60° step back to level) so no step is longer than 75°, except
/// the one from +75° to −75° pitch, whose step lasts longer in proportion.
const TILTS_DEG: [(f64, f64); 8] = [
    (0.0, 0.0),
    (60.0, 0.0),
    (120.0, 0.0),
    (180.0, 0.0),
    (240.0, 0.0),
    (300.0, 0.0),
    (360.0, 75.0),
    (360.0, -75.0),
];

/// Share of a turn spent ramping the yaw rate up, and again down.
const RAMP_FRACTION: f64 = 1.0 / 6.0;

/// A tilt step of this many degrees lasts one turn: the step's peak rate (twice its mean over a
/// cycloidal step) is then 360°/`sweep_s`, below the turns' own rate.
const STEP_DEG_PER_SWEEP: f64 = 180.0;

/// The calibration motion: rest, then the cycle of tilted yaw turns, repeated.
#[derive(Debug, Clone)]
pub struct CalibrationPath {
    start: TrajectoryStart,
    roll: Schedule,
    pitch: Schedule,
    yaw_rate: Schedule,
    /// Length of one cycle, s; the motion at `static_s + k·cycle_s + τ` is that at `static_s + τ`.
    cycle_s: f64,
}

impl CalibrationPath {
    /// The motion after `start.static_s` at rest, one yaw turn lasting `sweep_s` (> 0).
    pub fn new(start: TrajectoryStart, sweep_s: f64) -> (Self, Landmarks) {
        let t0 = start.static_s;
        let mut roll = Schedule::new(0.0);
        let mut pitch = Schedule::new(0.0);
        let mut yaw_rate = Schedule::new(0.0);
        let ramp_s = RAMP_FRACTION * sweep_s;
        // The ramps turn the block half a ramp's worth each: the rest of the turn runs at a rate
        // that completes the 360°.
        let turn_rate = TAU / (sweep_s - ramp_s);
        let mut t = t0;
        let mut previous = (0.0, 0.0);
        let targets = TILTS_DEG.iter().map(Some).chain([None]);
        for target in targets {
            let (to_roll, to_pitch) = target.copied().unwrap_or((360.0, 0.0));
            let step_deg = f64::max((to_roll - previous.0).abs(), (to_pitch - previous.1).abs());
            if step_deg > 0.0 {
                let step_s = sweep_s * step_deg / STEP_DEG_PER_SWEEP;
                roll.step_to(t, step_s, f64::to_radians(to_roll));
                pitch.step_to(t, step_s, f64::to_radians(to_pitch));
                t += step_s;
            }
            previous = (to_roll, to_pitch);
            if target.is_some() {
                yaw_rate.step_to(t, ramp_s, turn_rate);
                yaw_rate.step_to(t + sweep_s - ramp_s, ramp_s, 0.0);
                t += sweep_s;
            }
        }
        let path = Self {
            start,
            roll,
            pitch,
            yaw_rate,
            cycle_s: t - t0,
        };
        let landmarks = Landmarks {
            lift_off_s: f64::INFINITY,
            touchdown_s: f64::INFINITY,
            end_s: f64::INFINITY,
        };
        (path, landmarks)
    }

    /// Length of one cycle of turns, s.
    pub fn cycle_s(&self) -> f64 {
        self.cycle_s
    }

    /// The true state at time `t` seconds (t ≥ 0).
    pub fn sample(&self, t: f64) -> TruthState {
        let t0 = self.start.static_s;
        let (cycles, tau) = if t > t0 {
            let since = t - t0;
            let cycles = (since / self.cycle_s).floor();
            (cycles, t0 + (since - cycles * self.cycle_s))
        } else {
            (0.0, t)
        };
        let r = self.roll.sample(tau);
        let p = self.pitch.sample(tau);
        let y = self.yaw_rate.sample(tau);
        // Each cycle ends rolled a whole turn and yawed eight: the same attitude as it began. Roll is
        // reported within ±180°, yaw keeps counting turns (it is not wrapped in any scenario).
        let roll = (r.value + PI).rem_euclid(TAU) - PI;
        let yaw = self.start.heading_rad + y.integral + cycles * TAU * TILTS_DEG.len() as f64;
        let (attitude, angular_rate_b) =
            attitude_and_body_rate([roll, p.value, yaw], [r.rate, p.rate, y.value]);
        let zero = Vector3::zeros();
        TruthState {
            time_s: t,
            attitude,
            euler_rad: [roll, p.value, yaw],
            angular_rate_b,
            specific_force_b: specific_force_b(&attitude, &zero),
            velocity_n: zero,
            acceleration_n: zero,
            latitude_rad: self.start.latitude_rad,
            longitude_rad: self.start.longitude_rad,
            altitude_m: self.start.altitude_m,
            foot_load: 0.0,
            stance: t <= t0,
            rotor: RotorState::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn start() -> TrajectoryStart {
        TrajectoryStart {
            latitude_rad: 0.8,
            longitude_rad: 0.15,
            altitude_m: 488.0,
            heading_rad: 0.3,
            static_s: 3.0,
            uav_flight_s: None,
            calibration_sweep_s: 6.0,
            multirotor: Default::default(),
        }
    }

    #[test]
    fn a_cycle_lasts_about_a_minute_and_returns_to_its_start() {
        let (path, _) = CalibrationPath::new(start(), 6.0);
        // Eight turns of 6 s; tilt steps of 60° (5), 75°, 150° and 75°: 600° at 180° per turn.
        let expected = 8.0 * 6.0 + 6.0 * 600.0 / 180.0;
        assert!(
            (path.cycle_s() - expected).abs() < 1e-9,
            "{}",
            path.cycle_s()
        );
        let begin = path.sample(3.0);
        let end = path.sample(3.0 + path.cycle_s() - 1e-9);
        assert!(begin.attitude.angle_to(&end.attitude) < 1e-6);
        assert!(end.angular_rate_b.norm() < 1e-6);
        let later = path.sample(3.0 + 2.5 * path.cycle_s());
        let same = path.sample(3.0 + 0.5 * path.cycle_s());
        assert!(later.attitude.angle_to(&same.attitude) < 1e-9);
    }

    #[test]
    fn rates_stay_far_inside_the_gyro_full_scale_and_nothing_moves() {
        let (path, _) = CalibrationPath::new(start(), 6.0);
        let mut peak = 0.0f64;
        let steps = (path.cycle_s() * 100.0) as usize;
        for k in 0..steps {
            let s = path.sample(3.0 + k as f64 / 100.0);
            peak = peak.max(s.angular_rate_b.norm());
            assert_eq!(s.velocity_n, Vector3::zeros());
            assert!((s.specific_force_b.norm() - rins_earth::STANDARD_GRAVITY).abs() < 1e-9);
        }
        // A turn runs at 360° over the turn less one ramp, 72 °/s; the step that rolls 60° while
        // pitching 75° peaks at √(48² + 60²) = 76.8 °/s. The simulated gyros reach 300 °/s.
        assert!(
            (peak.to_degrees() - 76.8).abs() < 0.5,
            "{}",
            peak.to_degrees()
        );
        assert!(path.sample(1.0).stance && !path.sample(10.0).stance);
    }

    #[test]
    fn the_body_rate_is_the_derivative_of_the_attitude() {
        let (path, _) = CalibrationPath::new(start(), 6.0);
        let h = 1e-5;
        for k in 0..400 {
            let t = 3.0 + 0.17 * k as f64;
            let a = path.sample(t).attitude;
            let b = path.sample(t + h).attitude;
            let numeric = (a.inverse() * b).scaled_axis() / h;
            let exact = path.sample(t + 0.5 * h).angular_rate_b;
            assert!(
                (numeric - exact).norm() < 1e-5,
                "t {t}: {numeric} vs {exact}"
            );
        }
    }

    #[test]
    fn the_field_directions_cover_the_sphere() {
        let (path, _) = CalibrationPath::new(start(), 6.0);
        // Field at 60° dip; the smallest eigenvalue of the mean outer product of the body-frame
        // directions is 1/3 for a uniform sphere and 0 for a plane.
        let field = Vector3::new(0.5, 0.0, 3f64.sqrt() / 2.0);
        let mut moment = nalgebra::Matrix3::zeros();
        let n = (path.cycle_s() * 100.0) as usize;
        for k in 0..n {
            let s = path.sample(3.0 + k as f64 / 100.0);
            let m = s.attitude.inverse_transform_vector(&field);
            moment += m * m.transpose() / n as f64;
        }
        let smallest = moment.symmetric_eigenvalues().min();
        assert!(smallest > 0.25, "{moment}");
    }
}
