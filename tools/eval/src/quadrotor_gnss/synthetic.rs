//! A turning, swaying minute of flight for the tests: the units at 120 Hz (rate and specific
//! force), the reference at 10 Hz with its position at an antenna and stamped early.

use nalgebra::{Matrix3, Vector3};

use super::antenna::{Antenna, GRAVITY_MPS2, attitude};
use super::cross_validation::Choice;
use super::reference_check::rotation_vector;
use super::{FlightResult, RunScores};
use crate::datasets::quadrotor::TruthRow;
use crate::quadrotor_ahrs::mounting::Paired;
use crate::quadrotor_nav::frames::{BodySample, Motion};

/// Roll, pitch and heading at `t`, rad.
pub fn euler(t: f64) -> [f64; 3] {
    [0.2 * (1.3 * t).sin(), 0.15 * (0.9 * t + 1.0).sin(), 0.6 * t]
}

fn position(t: f64) -> Vector3<f64> {
    Vector3::new(
        3.0 * (0.5 * t).sin(),
        2.0 * (0.7 * t).cos(),
        0.5 * (1.1 * t).sin(),
    )
}

fn acceleration(t: f64) -> Vector3<f64> {
    Vector3::new(
        -0.75 * (0.5 * t).sin(),
        -0.98 * (0.7 * t).cos(),
        -0.605 * (1.1 * t).sin(),
    )
}

/// Body to NED at `t`.
pub fn rotation(t: f64) -> Matrix3<f64> {
    let [r, p, y] = euler(t);
    attitude(r, p, y)
}

/// The flight: `arm` from the units to the antenna (body, m), the reference's position stamped
/// `lead_s` early, and `roll_error` (rad, of time) added to the reference's roll.
pub fn flight(
    arm: [f64; 3],
    lead_s: f64,
    roll_error: impl Fn(f64) -> f64,
) -> (Vec<TruthRow>, Motion) {
    let dt = 1.0 / 120.0;
    let samples = (0..(60.0 / dt) as usize)
        .map(|j| {
            let t = j as f64 * dt;
            let f =
                rotation(t).transpose() * (acceleration(t) - Vector3::new(0.0, 0.0, GRAVITY_MPS2));
            // The rate over the sample's interval, which ends at its time.
            let turn = rotation_vector(&(rotation(t - dt).transpose() * rotation(t)));
            BodySample {
                gyro_rps: (turn / dt).into(),
                accel_mps2: f.into(),
            }
        })
        .collect();
    let truth = (0..600)
        .map(|k| {
            let t = k as f64 * 0.1;
            let [roll, pitch, heading] = euler(t);
            let p = position(t + lead_s) + rotation(t + lead_s) * Vector3::from(arm);
            TruthRow {
                t_s: t,
                distance_m: 0.0,
                speed_mps: 0.0,
                heading_rad: heading.rem_euclid(std::f64::consts::TAU),
                pitch_rad: pitch,
                roll_rad: roll + roll_error(t),
                height_m: -p[2],
                north_m: p[0],
                east_m: p[1],
                down_m: p[2],
            }
        })
        .collect();
    (
        truth,
        Motion {
            t0_s: 0.0,
            dt_s: dt,
            samples,
        },
    )
}

/// A flight's result with nothing in it but its fused run: the solution's `paired` rows, the gyro
/// bias it ended with and its raw roll/pitch RMSE.
pub fn flight_result(
    paired: Paired,
    final_gyro_bias_rps: [f64; 3],
    roll_pitch_rmse_deg: f64,
) -> FlightResult {
    let run = RunScores {
        imu: None,
        roll_pitch_rmse_deg,
        heading_rmse_deg: f64::NAN,
        horizontal_rmse_m: f64::NAN,
        end_horizontal_error_m: f64::NAN,
        fixes_applied: 0,
        fixes_outliers: 0,
        rejections: 0,
        paired,
        final_gyro_bias_rps,
    };
    FlightResult {
        name: String::new(),
        duration_s: 60.0,
        single: Vec::new(),
        fused: run,
        median_single_end_error_m: f64::NAN,
        drift_setting: Choice {
            candidate: 0,
            drift_slack: 0.0,
            drift_threshold: 0.0,
        },
        tilt_setting: String::new(),
        antenna: Antenna::default(),
        fused_roll_pitch_rmse_mounted_deg: f64::NAN,
        fused_roll_pitch_rmse_mounted_in_sample_deg: f64::NAN,
        fused_window_rmse_deg: [None; 3],
        scored: None,
        live: None,
        reference_check: Default::default(),
    }
}
