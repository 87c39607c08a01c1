//! The attitude filters a user would pick instead of rins, run on the same motion from the same
//! start: Madgwick's gradient-descent filter (S. O. H. Madgwick, A. J. L. Harrison,
//! R. Vaidyanathan, 2011) and Mahony's explicit complementary filter (R. Mahony, T. Hamel,
//! J.-M. Pflimlin, 2008), as `reference_algorithms` implements them (rate and specific force only:
//! the recordings have no magnetometer the filters could use).
//!
//! The filters hold the body → earth rotation of an earth frame whose z axis points up
//! (along the specific force at rest). The motion is in the vehicle's FRD axes and rins's
//! attitude is body → NED; NED turned by 180° about north is such a frame (north, west, up), so
//! the motion goes in unchanged and `q_ned = R_x(π)⁻¹ · q_up`.

use std::f64::consts::PI;

use nalgebra::{UnitQuaternion, Vector3};
use rins_navigator::attitude::quaternion_from_euler;
use serde::Serialize;

use super::reference_algorithms::{Correction, MadgwickImu, MahonyImu};
use super::run::{AttitudeTrace, first_sample_after};
use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::run::Start;

/// Madgwick's default gain β, rad/s, as in Madgwick's published code and the common libraries.
pub const MADGWICK_DEFAULT_BETA: f64 = 0.1;
/// Mahony's default proportional gain, rad/s, as in Madgwick's published code of Mahony's filter
/// and the common libraries.
pub const MAHONY_DEFAULT_KP: f64 = 0.5;
/// Mahony's default integral gain, rad/s²: none, as in the same code.
pub const MAHONY_DEFAULT_KI: f64 = 0.0;

/// Madgwick's β tried by the cross-validation, rad/s: √(3/4) times a gyro error of 0.7 °/s (the
/// size of these units' biases) to 20 °/s, the default among them.
pub const MADGWICK_BETAS: [f64; 4] = [0.01, 0.03, MADGWICK_DEFAULT_BETA, 0.3];
/// Mahony's kp tried: time constants of 33 s to 0.5 s, the default among them.
pub const MAHONY_KPS: [f64; 4] = [0.03, 0.1, MAHONY_DEFAULT_KP, 2.0];
/// Mahony's ki tried: none (the default), and a gyro-bias integrator of two speeds.
pub const MAHONY_KIS: [f64; 3] = [MAHONY_DEFAULT_KI, 0.01, 0.1];

/// One reference filter with its gains.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "filter", rename_all = "snake_case")]
pub enum ReferenceFilter {
    /// Madgwick's gradient-descent filter.
    Madgwick {
        /// Gain of the gradient step, rad/s.
        beta: f64,
    },
    /// Mahony's explicit complementary filter.
    Mahony {
        /// Proportional gain, rad/s.
        kp: f64,
        /// Integral gain, rad/s².
        ki: f64,
    },
}

impl ReferenceFilter {
    /// Short name for reports, e.g. `Madgwick beta 0.1`.
    pub fn name(&self) -> String {
        match self {
            Self::Madgwick { beta } => format!("Madgwick beta {beta}"),
            Self::Mahony { kp, ki } => format!("Mahony kp {kp} ki {ki}"),
        }
    }
}

/// Madgwick's grid and the position of the default in it.
pub fn madgwick_grid() -> (Vec<ReferenceFilter>, usize) {
    let grid: Vec<ReferenceFilter> = MADGWICK_BETAS
        .iter()
        .map(|&beta| ReferenceFilter::Madgwick { beta })
        .collect();
    let default = grid
        .iter()
        .position(|f| {
            *f == ReferenceFilter::Madgwick {
                beta: MADGWICK_DEFAULT_BETA,
            }
        })
        .unwrap_or(0);
    (grid, default)
}

/// Mahony's grid (every kp with every ki) and the position of the default in it.
pub fn mahony_grid() -> (Vec<ReferenceFilter>, usize) {
    let grid: Vec<ReferenceFilter> = MAHONY_KPS
        .iter()
        .flat_map(|&kp| {
            MAHONY_KIS
                .iter()
                .map(move |&ki| ReferenceFilter::Mahony { kp, ki })
        })
        .collect();
    let default = grid
        .iter()
        .position(|f| {
            *f == ReferenceFilter::Mahony {
                kp: MAHONY_DEFAULT_KP,
                ki: MAHONY_DEFAULT_KI,
            }
        })
        .unwrap_or(0);
    (grid, default)
}

/// One run of a reference filter.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReferenceRun {
    /// Attitude over the run, body → NED.
    pub trace: AttitudeTrace,
    /// Samples whose specific force was zero: the filter could only integrate the rate.
    pub samples_without_force: usize,
}

/// The NED → up-frame rotation (180° about north).
fn up_from_ned() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), PI)
}

/// One reference filter in its state.
enum State {
    Madgwick(MadgwickImu),
    Mahony(MahonyImu),
}

impl State {
    fn new(filter: ReferenceFilter, dt_s: f64, attitude_up: UnitQuaternion<f64>) -> Self {
        match filter {
            ReferenceFilter::Madgwick { beta } => {
                Self::Madgwick(MadgwickImu::new(dt_s, beta, attitude_up))
            }
            ReferenceFilter::Mahony { kp, ki } => {
                Self::Mahony(MahonyImu::new(dt_s, kp, ki, attitude_up))
            }
        }
    }

    fn update(&mut self, rate_rps: &Vector3<f64>, force: &Vector3<f64>) -> Correction {
        match self {
            Self::Madgwick(f) => f.update(rate_rps, force),
            Self::Mahony(f) => f.update(rate_rps, force),
        }
    }

    fn attitude_up(&self) -> UnitQuaternion<f64> {
        match self {
            Self::Madgwick(f) => f.attitude(),
            Self::Mahony(f) => f.attitude(),
        }
    }
}

/// Runs `filter` on `motion` from the airframe's attitude at `start` turned by the inverse of the
/// unit's `mounting` (`C_nav←vehicle = C_nav←unit · mounting`), as rins's runs start; every
/// sample after the start time is applied once, at the motion's sample period.
pub fn run_reference(
    motion: &Motion,
    start: &Start,
    filter: ReferenceFilter,
    mounting: &UnitQuaternion<f64>,
) -> ReferenceRun {
    let [roll, pitch, heading] = start.euler_rad;
    let attitude = quaternion_from_euler(roll, pitch, heading) * mounting.inverse();
    let up = up_from_ned();
    let mut state = State::new(filter, motion.dt_s, up * attitude);
    let mut run = ReferenceRun::default();
    run.trace.t_s.push(start.t_s);
    run.trace.attitude.push(attitude);
    let first = first_sample_after(motion, start.t_s);
    for (j, sample) in motion.samples.iter().enumerate().skip(first) {
        let gyro = Vector3::from(sample.gyro_rps);
        let force = Vector3::from(sample.accel_mps2);
        if state.update(&gyro, &force) == Correction::RateOnly {
            run.samples_without_force += 1;
        }
        run.trace.t_s.push(motion.time(j));
        run.trace.attitude.push(up.inverse() * state.attitude_up());
    }
    run
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor_nav::frames::BodySample;
    use rins_navigator::attitude::{euler_from_quaternion, wrap_pi};

    const G: f64 = 9.81;
    const DT: f64 = 0.01;

    fn start(euler_rad: [f64; 3]) -> Start {
        Start {
            row: 0,
            t_s: 0.0,
            euler_rad,
            velocity_ned: [0.0; 3],
            height_m: 0.0,
            ned_m: [0.0; 3],
        }
    }

    /// `n` samples of a vehicle held at roll `roll` and zero pitch while it turns about the
    /// vertical at `yaw_rate`: body rate `(0, sin φ, cos φ) ψ̇` and specific force
    /// `(0, −g sin φ, −g cos φ)`, both constant in FRD.
    fn turning(roll: f64, yaw_rate: f64, n: usize) -> Motion {
        let sample = BodySample {
            gyro_rps: [0.0, roll.sin() * yaw_rate, roll.cos() * yaw_rate],
            accel_mps2: [0.0, -G * roll.sin(), -G * roll.cos()],
        };
        // Sample j ends at (j + 1) dt: the first one is the first after a start at 0.
        Motion {
            t0_s: DT,
            dt_s: DT,
            samples: vec![sample; n],
        }
    }

    #[test]
    fn the_defaults_are_in_the_grids() {
        let (madgwick, d) = madgwick_grid();
        assert_eq!(madgwick[d].name(), "Madgwick beta 0.1");
        let (mahony, d) = mahony_grid();
        assert_eq!(mahony.len(), 12);
        assert_eq!(mahony[d].name(), "Mahony kp 0.5 ki 0");
    }

    /// A constant turn with the gravity direction consistent with the attitude: the correction
    /// is zero (Mahony) or a normalised quaternion step of β dt, a turn of 2 β dt, in the
    /// direction of rounding noise (Madgwick's gradient is normalised, so the tilt dithers
    /// within that), and the heading follows ψ̇ t up to the filters' first-order integration,
    /// which shortens each step's angle by (ω dt)³/12.
    #[test]
    fn a_constant_turn_keeps_the_tilt_and_follows_the_heading() {
        let (roll, yaw_rate, n) = (20_f64.to_radians(), 0.5, 2000);
        let motion = turning(roll, yaw_rate, n);
        let integration = n as f64 * (yaw_rate * DT).powi(3) / 12.0;
        for (filter, step) in [
            (ReferenceFilter::Madgwick { beta: 0.1 }, 2.0 * 0.1 * DT),
            (ReferenceFilter::Mahony { kp: 0.5, ki: 0.1 }, 1e-9),
        ] {
            let run = run_reference(
                &motion,
                &start([roll, 0.0, 0.3]),
                filter,
                &UnitQuaternion::identity(),
            );
            assert_eq!(run.trace.t_s.len(), n + 1);
            assert_eq!(run.samples_without_force, 0);
            let t_end = run.trace.t_s[n];
            assert!((t_end - n as f64 * DT).abs() < 1e-9);
            let [r, p, y] = euler_from_quaternion(&run.trace.attitude[n]);
            assert!((r - roll).abs() < step, "{filter:?}: roll {r}");
            assert!(p.abs() < step, "{filter:?}: pitch {p}");
            let heading_error = wrap_pi(y - (0.3 + yaw_rate * t_end));
            let bound = integration + step;
            assert!(
                heading_error.abs() < bound,
                "{filter:?}: {heading_error} > {bound}"
            );
        }
    }

    /// Standing level but started 5° off in roll: Madgwick turns towards gravity at 2β rad/s and
    /// ends within one step (2 β dt) of it; Mahony's error decays as e^(−kp t).
    #[test]
    fn a_tilt_error_decays_as_each_filter_says() {
        let motion = turning(0.0, 0.0, 2000);
        let from = start([5_f64.to_radians(), 0.0, 0.0]);
        let identity = UnitQuaternion::identity();
        let beta = 0.1;
        let madgwick = run_reference(
            &motion,
            &from,
            ReferenceFilter::Madgwick { beta },
            &identity,
        );
        let [r, p, _] = euler_from_quaternion(&madgwick.trace.attitude[2000]);
        let step = 2.0 * beta * DT;
        assert!(r.abs() < step && p.abs() < step, "Madgwick {r} {p}");
        let kp = 0.5;
        let mahony = run_reference(
            &motion,
            &from,
            ReferenceFilter::Mahony { kp, ki: 0.0 },
            &identity,
        );
        let [r, _, _] = euler_from_quaternion(&mahony.trace.attitude[2000]);
        let expected = 5_f64.to_radians() * (-kp * 20.0).exp();
        assert!(r.abs() < 2.0 * expected, "Mahony roll {r} vs {expected}");
    }

    #[test]
    fn a_zero_specific_force_integrates_the_rate_and_is_counted() {
        let mut motion = turning(0.0, 0.2, 100);
        for s in &mut motion.samples {
            s.accel_mps2 = [0.0; 3];
        }
        let run = run_reference(
            &motion,
            &start([0.0; 3]),
            ReferenceFilter::Madgwick { beta: 0.1 },
            &UnitQuaternion::identity(),
        );
        assert_eq!(run.samples_without_force, 100);
        let [_, _, y] = euler_from_quaternion(&run.trace.attitude[100]);
        assert!((y - 0.2).abs() < 1e-6, "{y}");
    }
}
