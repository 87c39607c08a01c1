//! The public recordings the evaluations run on, turned into rins's own recordings: raw IMU
//! frames in converter counts as the sensor block would send them, the reference as truth
//! samples, and a configuration that describes the block (`rins import`).
//!
//! - [`quadrotor`]: a four-IMU quadrotor flight. Every unit's triads become channels of one
//!   redundant block (4 units: 12 gyro and 12 accelerometer channels), each channel in its unit's
//!   own axes; the configuration gives each channel's axis in the vehicle frame, so that fusion's
//!   equal-weight least squares over the channels is the evaluation's fused solution.
//! - [`pyshoe`]: a foot-mounted walk, one triad, with the Vicon position as truth.
//! - [`counts`]: SI values to 16-bit counts, and the full scales chosen per recording.
//! - [`fragment`]: the configuration text.
//!
//! Everything here is a pure function of the loaded trial; `rins import` writes the files.

pub mod counts;
pub mod fragment;
pub mod pyshoe;
pub mod quadrotor;

use ipc_types::{RawImu, Truth};
use serde::Serialize;

pub use counts::Scales;

/// Added to a frame's device time (µs, × 1000) to give its receive time (ns): the receive times
/// increase with the device times, and none is zero (a zero receive time reads as "not stamped").
pub const RX_OFFSET_NS: u64 = 1_000_000_000;

/// The receive time written for a frame of device time `device_time_us`, ns.
pub fn rx_ns(device_time_us: u64) -> u64 {
    device_time_us
        .saturating_mul(1000)
        .saturating_add(RX_OFFSET_NS)
}

/// A clock offset the loader found and removed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ClockOffset {
    /// Which clocks: e.g. `truth` or `IMU_2`.
    pub clock: String,
    /// Added to that file's times to put them on the recording's time base, s.
    pub offset_s: f64,
    /// How it was found.
    pub how: String,
}

/// A count of one kind of repair.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct RepairCount {
    /// What was repaired, e.g. `repeated_timestamps`.
    pub kind: String,
    /// How many times.
    pub count: usize,
}

/// What quantising to counts cost, per sensor.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Quantisation {
    /// Largest |count · lsb − value| of any gyro channel, rad/s.
    pub gyro_max_error_rps: f64,
    /// Largest |count · lsb − value| of any accelerometer channel, m/s².
    pub accel_max_error_mps2: f64,
    /// Readings outside the converter's range, clamped to a rail (zero by the choice of scale).
    pub clamped: u64,
    /// Channel readings that were missing (not finite): marked invalid in the frame's mask.
    pub invalid_readings: u64,
}

/// One recording, imported.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportedRun {
    /// `<group>/path_<N>` for a flight, the file stem for a walk.
    pub name: String,
    /// The raw IMU frames, in device-time order.
    pub imu: Vec<RawImu>,
    /// The reference, in device-time order.
    pub truth: Vec<Truth>,
    /// A complete configuration file for the recording (TOML).
    pub config_fragment: String,
    /// The converter ranges chosen.
    pub scales: Scales,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// What quantising cost.
    pub quantisation: Quantisation,
    /// Clock offsets the loader removed.
    pub clock_offsets: Vec<ClockOffset>,
    /// What the loader repaired, by kind (only kinds that occurred).
    pub repairs: Vec<RepairCount>,
    /// What the loader and the import noticed.
    pub notes: Vec<String>,
}

/// The scalar-first components of a unit quaternion.
pub(crate) fn wxyz(q: &nalgebra::UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// Central differences of `positions` over `times` (one-sided at the ends; zero for a single
/// sample or a step that is not positive), per axis.
pub(crate) fn central_difference(times: &[f64], positions: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let n = times.len().min(positions.len());
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n.saturating_sub(1)));
            let span = times[b] - times[a];
            if b == a || span.is_nan() || span <= 0.0 {
                return [0.0; 3];
            }
            std::array::from_fn(|k| (positions[b][k] - positions[a][k]) / span)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn velocity_is_the_central_difference_and_one_sided_at_the_ends() {
        let t = [0.0, 0.1, 0.2, 0.3];
        let p: Vec<[f64; 3]> = t.iter().map(|&t| [2.0 * t, -t * t, 0.0]).collect();
        let v = central_difference(&t, &p);
        assert!((v[0][0] - 2.0).abs() < 1e-12);
        assert!((v[1][1] - -0.2).abs() < 1e-12, "{:?}", v[1]);
        assert!((v[3][1] - -0.5).abs() < 1e-12, "{:?}", v[3]);
        assert_eq!(central_difference(&[1.0], &[[1.0; 3]]), vec![[0.0; 3]]);
    }

    #[test]
    fn receive_times_grow_with_device_times_and_are_never_zero() {
        assert_eq!(rx_ns(0), RX_OFFSET_NS);
        assert!(rx_ns(1) > rx_ns(0));
    }
}
