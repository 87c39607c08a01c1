//! The drag model's heading switch (`[navigator.tilt] drag_heading`) chosen leave-one-flight-out.
//!
//! Rotor drag ties the heading to the direction of the velocity through the air, and a
//! GNSS-aided filter's velocity is over the ground: in wind, the two disagree by up to wind over
//! airspeed. Whether the drag should still correct the heading is therefore a property of the
//! flights, and it is learnt from them like every other setting: each flight gets the setting
//! whose fused roll/pitch RMSE on the first pass (no gyro prior; each flight scored with the
//! mounting fitted on the flights other than itself, as the report scores) is the smaller mean
//! over the other flights.

use rins_navigator::aiding::tilt::{TiltAidingConfig, TiltModel};

use super::FlightResult;
use crate::leave_one_out::choose_without_each;
use crate::quadrotor_ahrs::SETTLE_S;
use crate::quadrotor_ahrs::mounting::{Paired, fit_mounting, roll_pitch_rmse_deg};

/// The settings tried: the profile's own only when its tilt updates do not use the drag model,
/// where the switch does nothing.
pub fn settings(tilt: &TiltAidingConfig) -> Vec<bool> {
    if tilt.enabled && tilt.model == TiltModel::Drag {
        vec![false, true]
    } else {
        vec![tilt.drag_heading]
    }
}

/// `first_pass[s][f]`: flight `f`'s first pass under setting `s` (every row as long as the first).
/// Returns, per flight, the index of the setting chosen on the other flights.
pub fn choose(first_pass: &[Vec<FlightResult>]) -> Vec<usize> {
    let flights = first_pass.first().map_or(0, Vec::len);
    let scores: Vec<Vec<f64>> = (0..flights)
        .map(|f| {
            first_pass
                .iter()
                .map(|runs| mounted_rmse_deg(runs, f))
                .collect()
        })
        .collect();
    choose_without_each(&scores)
}

/// Flight `f`'s fused roll/pitch RMSE with the mounting fitted on the other flights, degrees: the
/// figure the evaluation reports, on the first pass.
fn mounted_rmse_deg(runs: &[FlightResult], f: usize) -> f64 {
    let others: Vec<&Paired> = runs
        .iter()
        .enumerate()
        .filter(|&(g, _)| g != f)
        .map(|(_, r)| &r.fused.paired)
        .collect();
    match runs.get(f) {
        Some(run) if !others.is_empty() => {
            roll_pitch_rmse_deg(&run.fused.paired, fit_mounting(&others, SETTLE_S), 0.0)
        }
        _ => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quadrotor_gnss::synthetic::flight_result;
    use rins_navigator::attitude::quaternion_from_euler;

    #[test]
    fn the_switch_is_tried_only_where_the_drag_model_runs() {
        let mut tilt = TiltAidingConfig {
            enabled: true,
            model: TiltModel::Drag,
            ..TiltAidingConfig::default()
        };
        assert_eq!(settings(&tilt), vec![false, true]);
        tilt.model = TiltModel::Gravity;
        tilt.drag_heading = true;
        assert_eq!(settings(&tilt), vec![true]);
        tilt.model = TiltModel::Drag;
        tilt.enabled = false;
        assert_eq!(settings(&tilt), vec![true]);
    }

    /// A flight whose fused roll is off by ±`error_deg`, alternating row by row (no mounting
    /// can take it out), over a minute at 1 Hz.
    fn flight(error_deg: f64) -> FlightResult {
        let mut paired = Paired::default();
        for k in 0..60 {
            let (roll, pitch) = (0.02 * k as f64, -0.01 * k as f64);
            let error = error_deg.to_radians() * if k % 2 == 0 { 1.0 } else { -1.0 };
            let solution = quaternion_from_euler(roll + error, pitch, 0.3);
            paired.push(k as f64, solution, roll, pitch);
        }
        flight_result(paired, [0.0; 3], f64::NAN)
    }

    #[test]
    fn each_flight_gets_what_the_others_prefer_not_what_it_prefers_itself() {
        // Setting 1 is better on three flights out of four; the fourth prefers setting 0 by a
        // wide margin, which must not decide its own choice.
        let error = [[1.0, 0.8], [1.0, 0.8], [1.0, 0.8], [0.5, 3.0]];
        let first_pass: Vec<Vec<FlightResult>> = (0..2)
            .map(|s| error.iter().map(|e| flight(e[s])).collect())
            .collect();
        let rmse = mounted_rmse_deg(&first_pass[0], 3);
        assert!((rmse - 0.5 / 2_f64.sqrt()).abs() < 1e-3, "{rmse}");
        // Without flight 3, setting 1 wins; without any one of the others, flight 3's 3.0 makes
        // the mean of setting 1 (0.8 + 0.8 + 3.0) / 3 larger than setting 0's (1 + 1 + 0.5) / 3.
        assert_eq!(choose(&first_pass), vec![0, 0, 0, 1]);
    }
}
