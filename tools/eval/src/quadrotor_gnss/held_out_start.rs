//! What a flight's runs know at t0, learnt from the other flights: each series' mounting on the
//! airframe (fitted as `--mode ahrs` fits it) and its gyro bias (the mean of the biases the same
//! series ended the other flights with), both from a first pass that started every run from the
//! airframe's attitude with no bias known.
//!
//! A series is the fused units or one unit (by file number): each is its own instrument with its
//! own mounting and bias, learnt only from the flights that carry it.

use super::run::StartKnowledge;
use super::{FlightResult, RunScores};
use crate::quadrotor_ahrs::SETTLE_S;
use crate::quadrotor_ahrs::cross_validation::gyro_prior;
use crate::quadrotor_ahrs::mounting::{Paired, fit_mounting, mounting_rotation};

/// The prior's σ as a multiple of the spread of the other flights' final biases: one spread, the
/// plain sample σ (no choice made on these flights).
pub const PRIOR_SIGMA_SCALE: f64 = 1.0;

/// One series' start and the mounting tilt it is scored with.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SeriesStart {
    /// Mounting tilt about x and y, rad.
    pub tilt_rad: [f64; 2],
    /// What the run is started with.
    pub known: StartKnowledge,
}

/// Every series' start in one flight.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FlightStarts {
    /// By unit file number.
    pub single: Vec<(usize, SeriesStart)>,
    /// The fused units.
    pub fused: SeriesStart,
}

impl FlightStarts {
    /// The start of series `imu` (`None`: fused); the nominal start when none was learnt.
    pub fn of(&self, imu: Option<usize>) -> SeriesStart {
        match imu {
            None => self.fused,
            Some(k) => self
                .single
                .iter()
                .find(|(u, _)| *u == k)
                .map(|(_, s)| *s)
                .unwrap_or_default(),
        }
    }
}

fn run_of(flight: &FlightResult, imu: Option<usize>) -> Option<&RunScores> {
    match imu {
        None => Some(&flight.fused),
        Some(k) => flight.single.iter().find(|r| r.imu == Some(k)),
    }
}

fn learnt(first_pass: &[FlightResult], f: usize, imu: Option<usize>) -> SeriesStart {
    let others: Vec<&RunScores> = first_pass
        .iter()
        .enumerate()
        .filter(|&(g, _)| g != f)
        .filter_map(|(_, flight)| run_of(flight, imu))
        .collect();
    if others.is_empty() {
        return SeriesStart::default();
    }
    let paired: Vec<&Paired> = others.iter().map(|r| &r.paired).collect();
    let tilt_rad = fit_mounting(&paired, SETTLE_S);
    let biases: Vec<[f64; 3]> = others.iter().map(|r| r.final_gyro_bias_rps).collect();
    SeriesStart {
        tilt_rad,
        known: StartKnowledge {
            mounting: mounting_rotation(tilt_rad),
            prior: gyro_prior(&biases, PRIOR_SIGMA_SCALE),
        },
    }
}

/// For each flight of `first_pass`, its series' starts learnt from the other flights.
pub fn held_out_starts(first_pass: &[FlightResult]) -> Vec<FlightStarts> {
    (0..first_pass.len())
        .map(|f| FlightStarts {
            single: first_pass[f]
                .single
                .iter()
                .filter_map(|r| r.imu)
                .map(|k| (k, learnt(first_pass, f, Some(k))))
                .collect(),
            fused: learnt(first_pass, f, None),
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor_ahrs::mounting::roll_pitch_rmse_deg;
    use crate::quadrotor_gnss::synthetic::flight_result;
    use rins_navigator::attitude::quaternion_from_euler;

    /// A flight whose fused solution is the reference turned by the mounting `tilt`, at 1 Hz,
    /// ending with gyro bias `bias`.
    fn flight(tilt: [f64; 2], roll_deg: f64, bias: [f64; 3]) -> FlightResult {
        let mut paired = Paired::default();
        let m_inv = mounting_rotation(tilt).inverse();
        for k in 0..60 {
            let (roll, pitch, yaw) = (roll_deg.to_radians(), (k as f64 * 0.01).sin(), 0.3);
            let vehicle = quaternion_from_euler(roll, pitch, yaw);
            paired.push(k as f64, vehicle * m_inv, roll, pitch);
        }
        flight_result(paired, bias, f64::NAN)
    }

    #[test]
    fn each_flight_starts_with_the_mounting_and_bias_of_the_others() {
        let tilt = [0.7_f64.to_radians(), -0.5_f64.to_radians()];
        let same = [
            flight(tilt, 2.0, [0.001, 0.0, 0.0]),
            flight(tilt, -3.0, [0.003, 0.0, 0.0]),
            flight(tilt, 5.0, [0.005, 0.0, 0.0]),
        ];
        let starts = held_out_starts(&same);
        for (f, s) in same.iter().zip(&starts) {
            // The airframe's mounting, learnt from the other flights, removes the whole error.
            let rmse = roll_pitch_rmse_deg(&f.fused.paired, s.fused.tilt_rad, 0.0);
            assert!(rmse < 1e-6, "{rmse}");
            assert_eq!(s.fused.known.mounting, mounting_rotation(s.fused.tilt_rad));
        }
        // Flight 0's prior is the mean of flights 1 and 2's final biases, σ their spread.
        let prior = starts[0]
            .fused
            .known
            .prior
            .expect("a prior from two flights");
        assert!((prior.bias_rps[0] - 0.004).abs() < 1e-12);
        assert!((prior.sigma_rps - 0.001_f64.max(0.05_f64.to_radians())).abs() < 1e-12);
        // A unit no other flight carries starts from nothing.
        assert_eq!(starts[0].of(Some(3)), SeriesStart::default());
        // A flight mounted otherwise than the two others keeps the difference held out.
        let odd = [
            flight(tilt, 2.0, [0.0; 3]),
            flight(tilt, -3.0, [0.0; 3]),
            flight([0.0, 0.0], 5.0, [0.0; 3]),
        ];
        let starts = held_out_starts(&odd);
        let held_out = roll_pitch_rmse_deg(&odd[2].fused.paired, starts[2].fused.tilt_rad, 0.0);
        let rms_tilt_deg = ((tilt[0].powi(2) + tilt[1].powi(2)) / 2.0)
            .sqrt()
            .to_degrees();
        assert!(
            (held_out - rms_tilt_deg).abs() < 0.02,
            "{held_out} vs {rms_tilt_deg}"
        );
    }
}
