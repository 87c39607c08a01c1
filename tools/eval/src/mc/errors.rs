//! Navigation errors against the simulator's truth, and their accumulation over a time window.

use nalgebra::{Quaternion, UnitQuaternion};
use rins_earth::{meridian_radius, prime_vertical_radius};
use rins_navigator::NavOutput;
use rins_navigator::attitude::{euler_from_quaternion, wrap_pi};
use rins_sim::TruthSample;
use serde::Serialize;

use crate::stats::RmsAccumulator;

/// Errors of one solution (solution − truth), in report units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NavErrors {
    /// Roll error, degrees.
    pub roll_deg: f64,
    /// Pitch error, degrees.
    pub pitch_deg: f64,
    /// Heading (yaw) error wrapped to (−180, 180], degrees.
    pub heading_deg: f64,
    /// North position error, m.
    pub north_m: f64,
    /// East position error, m.
    pub east_m: f64,
    /// Altitude error, m.
    pub altitude_m: f64,
}

fn quaternion(q: [f64; 4]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

impl NavErrors {
    /// Errors of `nav` against `truth`. Roll, pitch and heading are differences of the ZYX Euler
    /// angles (meaningful away from ±90° pitch; the UAV profile stays within ±10°). Position errors
    /// are the latitude/longitude differences scaled by the WGS84 radii at the true position.
    pub fn of(nav: &NavOutput, truth: &TruthSample) -> Self {
        let [rn, pn, yn] = euler_from_quaternion(&quaternion(nav.quaternion));
        let [rt, pt, yt] = euler_from_quaternion(&quaternion(truth.quaternion));
        let lat = truth.latitude_rad;
        let h = truth.altitude_m;
        Self {
            roll_deg: wrap_pi(rn - rt).to_degrees(),
            pitch_deg: (pn - pt).to_degrees(),
            heading_deg: wrap_pi(yn - yt).to_degrees(),
            north_m: (nav.lat - lat) * (meridian_radius(lat) + h),
            east_m: wrap_pi(nav.lon - truth.longitude_rad)
                * (prime_vertical_radius(lat) + h)
                * lat.cos(),
            altitude_m: nav.alt - h,
        }
    }

    /// Horizontal position error, m.
    pub fn horizontal_m(&self) -> f64 {
        self.north_m.hypot(self.east_m)
    }
}

/// RMS of the errors over a window, in report units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RmsErrors {
    /// Per-axis RMS of roll and pitch together, √(mean((Δφ² + Δθ²)/2)), degrees.
    pub roll_pitch_deg: f64,
    /// RMS heading error, degrees.
    pub heading_deg: f64,
    /// RMS of the horizontal error length √(Δn² + Δe²), m.
    pub horizontal_m: f64,
    /// RMS altitude error, m.
    pub altitude_m: f64,
}

/// What one window of one run produced.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WindowResult {
    /// Start of the window, s of device time.
    pub start_s: f64,
    /// Errors at the last tick of the window; `None` when there was no valid solution then.
    pub final_errors: Option<NavErrors>,
    /// RMS over the ticks of the window that had a solution (sampled every
    /// [`ERROR_SAMPLE_TICKS`] ticks); `None` when none had.
    pub rms: Option<RmsErrors>,
    /// Time inside the window without a valid solution (fuser short of channels), s.
    pub unsolved_s: f64,
    /// Time inside the window with some channel left out of the solution (dead, or excluded by
    /// the fuser's fault detection) or flagged (Suspect, detected-not-isolated), s. In a
    /// fault-free flight this is false-alarm time.
    pub degraded_s: f64,
}

/// Errors are sampled every this many IMU ticks for the RMS (100 Hz at 1 kHz): they change slowly,
/// and the Euler angles and radii cost more than a navigation step.
pub const ERROR_SAMPLE_TICKS: u64 = 10;

/// Accumulates errors from a start tick to the end of the flight; allocation-free.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Window {
    start_s: f64,
    roll_pitch: RmsAccumulator,
    heading: RmsAccumulator,
    horizontal: RmsAccumulator,
    altitude: RmsAccumulator,
    last: Option<NavErrors>,
    unsolved_ticks: u64,
    degraded_ticks: u64,
    tick_s: f64,
}

impl Window {
    pub fn new(start_s: f64, tick_s: f64) -> Self {
        Self {
            start_s,
            roll_pitch: RmsAccumulator::new(),
            heading: RmsAccumulator::new(),
            horizontal: RmsAccumulator::new(),
            altitude: RmsAccumulator::new(),
            last: None,
            unsolved_ticks: 0,
            degraded_ticks: 0,
            tick_s,
        }
    }

    /// One tick: `solution` is the navigator's output for it, `None` when there was none;
    /// `degraded` says some channel was left out. `sample` asks for the errors to enter the RMS;
    /// `is_last` forces their evaluation.
    pub fn push(
        &mut self,
        solution: Option<&NavOutput>,
        degraded: bool,
        truth: &TruthSample,
        sample: bool,
        is_last: bool,
    ) {
        self.degraded_ticks += u64::from(degraded);
        let Some(nav) = solution else {
            self.unsolved_ticks += 1;
            self.last = None;
            return;
        };
        if !(sample || is_last) {
            return;
        }
        let e = NavErrors::of(nav, truth);
        if sample {
            self.roll_pitch
                .push_squared(0.5 * (e.roll_deg.powi(2) + e.pitch_deg.powi(2)));
            self.heading.push(e.heading_deg);
            self.horizontal
                .push_squared(e.north_m.powi(2) + e.east_m.powi(2));
            self.altitude.push(e.altitude_m);
        }
        self.last = Some(e);
    }

    pub fn result(&self) -> WindowResult {
        let rms = match (
            self.roll_pitch.rms(),
            self.heading.rms(),
            self.horizontal.rms(),
            self.altitude.rms(),
        ) {
            (Some(roll_pitch_deg), Some(heading_deg), Some(horizontal_m), Some(altitude_m)) => {
                Some(RmsErrors {
                    roll_pitch_deg,
                    heading_deg,
                    horizontal_m,
                    altitude_m,
                })
            }
            _ => None,
        };
        WindowResult {
            start_s: self.start_s,
            final_errors: self.last,
            rms,
            unsolved_s: self.unsolved_ticks as f64 * self.tick_s,
            degraded_s: self.degraded_ticks as f64 * self.tick_s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::NavMode;
    use rins_navigator::attitude::quaternion_from_euler;

    fn nav_at(roll: f64, pitch: f64, yaw: f64, lat: f64, lon: f64, alt: f64) -> NavOutput {
        let q = quaternion_from_euler(roll, pitch, yaw);
        NavOutput {
            device_time_us: 0,
            quaternion: [q.w, q.i, q.j, q.k],
            velocity_ned: [0.0; 3],
            lat,
            lon,
            alt,
            mode: NavMode::Navigating,
            aiding: ipc_types::aiding::BARO | ipc_types::aiding::MAG,
            covariance_diag: [0.0; ipc_types::NAV_STATES],
            counts: Default::default(),
            gyro_bias_rps: [0.0; 3],
            accel_bias_mps2: [0.0; 3],
            integrity: ipc_types::Integrity::Ok,
            integrity_reasons: 0,
            resets: [0; rins_navigator::ekf::AidingSource::COUNT],
        }
    }

    fn truth_at(roll: f64, pitch: f64, yaw: f64, lat: f64, lon: f64, alt: f64) -> TruthSample {
        let q = quaternion_from_euler(roll, pitch, yaw);
        TruthSample {
            quaternion: [q.w, q.i, q.j, q.k],
            latitude_rad: lat,
            longitude_rad: lon,
            altitude_m: alt,
            ..TruthSample::default()
        }
    }

    #[test]
    fn errors_are_solution_minus_truth_in_report_units() {
        let lat = 47f64.to_radians();
        let truth = truth_at(0.1, -0.05, 3.1, lat, 0.15, 600.0);
        // 1 µrad north and east, heading across the ±180° cut.
        let nav = nav_at(
            0.1 + 1e-3,
            -0.05 - 2e-3,
            -3.1,
            lat + 1e-6,
            0.15 + 1e-6,
            602.5,
        );
        let e = NavErrors::of(&nav, &truth);
        assert!((e.roll_deg - 1e-3f64.to_degrees()).abs() < 1e-9, "{e:?}");
        assert!((e.pitch_deg + 2e-3f64.to_degrees()).abs() < 1e-9, "{e:?}");
        let expected_heading = (2.0 * std::f64::consts::PI - 6.2).to_degrees();
        assert!((e.heading_deg - expected_heading).abs() < 1e-9, "{e:?}");
        let rn = meridian_radius(lat) + 600.0;
        let re = (prime_vertical_radius(lat) + 600.0) * lat.cos();
        assert!((e.north_m - 1e-6 * rn).abs() < 1e-6, "{e:?}");
        assert!((e.east_m - 1e-6 * re).abs() < 1e-6, "{e:?}");
        assert!((e.altitude_m - 2.5).abs() < 1e-12);
        assert!((e.horizontal_m() - (1e-6 * rn).hypot(1e-6 * re)).abs() < 1e-6);
    }

    #[test]
    fn window_rms_final_and_unsolved_time() {
        let truth = truth_at(0.0, 0.0, 0.0, 0.5, 0.1, 100.0);
        let mut w = Window::new(2.0, 0.001);
        // Altitude errors +1, −1, +3 sampled; RMS √(11/3). The last one is not sampled but final.
        for (k, alt_err) in [1.0, -1.0, 3.0, 7.0].into_iter().enumerate() {
            let nav = nav_at(0.0, 0.0, 0.0, 0.5, 0.1, 100.0 + alt_err);
            w.push(Some(&nav), k == 1, &truth, k < 3, k == 3);
        }
        w.push(None, false, &truth, true, false);
        w.push(None, true, &truth, true, true);
        let r = w.result();
        assert!((r.rms.unwrap().altitude_m - (11.0f64 / 3.0).sqrt()).abs() < 1e-9);
        assert_eq!(r.final_errors, None, "no solution at the end");
        assert!((r.unsolved_s - 0.002).abs() < 1e-15);
        assert!((r.degraded_s - 0.002).abs() < 1e-15);
        assert_eq!(r.start_s, 2.0);
    }
}
