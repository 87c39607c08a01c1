//! The tilt updates' setting (`[navigator.tilt]`) chosen leave-one-flight-out, from a small set.
//!
//! The profile's tilt settings were chosen for flight without position aiding. With the receiver,
//! two things may change. Rotor drag ties the heading to the direction of the velocity through the
//! air, and the receiver's velocity is over the ground: in wind the two disagree by up to wind
//! over airspeed, which is why the profile's `drag_heading = "without_gnss"` drops that
//! information while fixes come in; whether it is worth keeping anyway is tried. And the receiver now levels the filter too, so the tilt
//! updates may be worth less (a larger σ) or nothing (off). Each flight gets the setting whose
//! fused roll/pitch RMSE on the first pass (no gyro prior; each flight scored with the mounting
//! fitted on the flights other than itself, as the report scores) is the smallest mean over the
//! other flights; ties go to the earlier setting, the profile's own.

use rins_navigator::aiding::tilt::{DragHeading, TiltAidingConfig, TiltModel};

use super::FlightResult;
use crate::leave_one_out::choose_without_each;
use crate::quadrotor_ahrs::SETTLE_S;
use crate::quadrotor_ahrs::mounting::{Paired, fit_mounting, roll_pitch_rmse_deg};

/// σ of the "looser" setting, m/s²: three times the profile's 1 m/s².
pub const LOOSE_SIGMA_MPS2: f64 = 3.0;

/// One candidate setting of the tilt updates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltSetting {
    /// Short name for the report.
    pub name: &'static str,
    /// The settings.
    pub tilt: TiltAidingConfig,
}

/// The settings tried, the profile's own first: with the drag's heading information always (or,
/// where the profile has that, never; drag model only), with σ [`LOOSE_SIGMA_MPS2`], and off (only
/// where the profile has them on).
pub fn settings(tilt: &TiltAidingConfig) -> Vec<TiltSetting> {
    let mut out = vec![TiltSetting {
        name: "profile",
        tilt: *tilt,
    }];
    if !tilt.enabled {
        return out;
    }
    if tilt.model == TiltModel::Drag {
        let (name, drag_heading) = match tilt.drag_heading {
            DragHeading::Always => ("drag heading never", DragHeading::Never),
            _ => ("drag heading always", DragHeading::Always),
        };
        out.push(TiltSetting {
            name,
            tilt: TiltAidingConfig {
                drag_heading,
                ..*tilt
            },
        });
    }
    out.push(TiltSetting {
        name: "sigma 3",
        tilt: TiltAidingConfig {
            sigma_mps2: LOOSE_SIGMA_MPS2,
            ..*tilt
        },
    });
    out.push(TiltSetting {
        name: "off",
        tilt: TiltAidingConfig {
            enabled: false,
            ..*tilt
        },
    });
    out
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
    fn the_profile_comes_first_and_the_heading_switch_only_with_the_drag_model() {
        let mut tilt = TiltAidingConfig {
            enabled: true,
            model: TiltModel::Drag,
            ..TiltAidingConfig::default()
        };
        let names = |t: &TiltAidingConfig| settings(t).iter().map(|s| s.name).collect::<Vec<_>>();
        assert_eq!(
            names(&tilt),
            ["profile", "drag heading always", "sigma 3", "off"]
        );
        let s = settings(&tilt);
        assert_eq!(s[0].tilt, tilt);
        assert!(s[1].tilt.drag_heading == DragHeading::Always && !s[3].tilt.enabled);
        assert_eq!(s[2].tilt.sigma_mps2, LOOSE_SIGMA_MPS2);
        tilt.model = TiltModel::Gravity;
        assert_eq!(names(&tilt), ["profile", "sigma 3", "off"]);
        tilt.enabled = false;
        assert_eq!(names(&tilt), ["profile"]);
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
