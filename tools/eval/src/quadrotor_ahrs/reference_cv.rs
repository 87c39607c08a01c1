//! The reference filters ([`super::reference_filter`]) and the naive fusion of the units' own
//! filters ([`super::peer_average`]), scored exactly as rins is (see [`super`]): the same rows, the
//! same mounting tilt fitted on the other flights after [`SETTLE_S`], the same RMSE.
//!
//! For each reference filter and flight F: every setting of its grid has run the fused motion of
//! every flight from the airframe's attitude; the setting with the lowest mean on the flights
//! other than F (mounting fitted on them) runs F again from the airframe's attitude turned by the
//! mounting of the other flights with F's units, and F is scored with it; each unit alone runs
//! with the same setting and its own mounting from the other flights that have it. The default
//! setting is scored the same way, without a choice. The filters have no gyro-bias prior
//! to take: Madgwick's IMU filter has no bias state, Mahony's integrator starts at zero.

use nalgebra::UnitQuaternion;
use serde::Serialize;

use super::cross_validation::{others_with_unit, same_units, training_score, without};
use super::mounting::{Paired, fit_mounting, mounting_rotation, roll_pitch_rmse_deg};
use super::reference_filter::{ReferenceFilter, madgwick_grid, mahony_grid, run_reference};
use super::windows::{self, WindowRmse};
use super::{CandidateFigure, Flight, FlightResult, SETTLE_S, pair};
use crate::datasets::quadrotor::MAX_IMUS;
use crate::quadrotor_nav::frames::Motion;

/// One setting of a reference filter on one flight.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ReferenceScore {
    /// The setting, e.g. `Madgwick beta 0.1`.
    pub setting: String,
    /// Fused units, roll/pitch RMSE, degrees.
    pub fused_roll_pitch_rmse_deg: f64,
    /// Each unit alone, by unit number 1..=4 (null when absent).
    pub single_roll_pitch_rmse_deg: [Option<f64>; MAX_IMUS],
    /// The fused RMSE over the windows of time since the start ([`windows::WINDOW_STARTS_S`]).
    pub fused_window_rmse_deg: WindowRmse,
    /// Samples of the scored runs with a zero specific force (rate integrated only).
    pub samples_without_force: usize,
}

/// A reference filter on one flight: the default setting and the setting chosen on the other
/// flights.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ReferenceFlight {
    /// The default setting.
    pub default: ReferenceScore,
    /// The setting chosen on the other flights.
    pub cross_validated: ReferenceScore,
}

/// A reference filter over every flight.
pub struct ReferenceOutcome {
    /// Per flight, in order.
    pub flights: Vec<ReferenceFlight>,
    /// Every setting's in-sample figure and how often it was chosen.
    pub grid: Vec<CandidateFigure>,
}

fn run_paired(
    flight: &Flight,
    motion: &Motion,
    filter: ReferenceFilter,
    mounting: &UnitQuaternion<f64>,
) -> (Paired, usize) {
    let run = run_reference(motion, &flight.start, filter, mounting);
    (
        pair(&run.trace, flight.start.t_s, &flight.rows),
        run.samples_without_force,
    )
}

/// Flight `f` scored with `filter`, its mountings fitted on `first` (the fused runs from the
/// airframe's attitude, per flight) and `singles` (the units' runs, per flight and position).
fn score(
    flights: &[Flight],
    f: usize,
    filter: ReferenceFilter,
    first: &[Paired],
    singles: &[Vec<Paired>],
) -> ReferenceScore {
    let flight = &flights[f];
    let tilt = fit_mounting(&same_units(flights, first, f, None), SETTLE_S);
    let (fused, mut samples_without_force) =
        run_paired(flight, &flight.fused, filter, &mounting_rotation(tilt));
    let mut single = [None; MAX_IMUS];
    for (k, &imu) in flight.imus.iter().enumerate() {
        let others = others_with_unit(flights, f, imu);
        if others.is_empty() {
            continue;
        }
        let same: Vec<&Paired> = others.iter().map(|&(g, j)| &singles[g][j]).collect();
        let unit_tilt = fit_mounting(&same, SETTLE_S);
        let (own, n) = run_paired(
            flight,
            &flight.singles[k],
            filter,
            &mounting_rotation(unit_tilt),
        );
        samples_without_force += n;
        single[imu - 1] = Some(roll_pitch_rmse_deg(&own, unit_tilt, 0.0));
    }
    ReferenceScore {
        setting: filter.name(),
        fused_roll_pitch_rmse_deg: roll_pitch_rmse_deg(&fused, tilt, 0.0),
        single_roll_pitch_rmse_deg: single,
        fused_window_rmse_deg: windows::of(&fused, tilt),
        samples_without_force,
    }
}

/// Scores the filter of `grid` on every flight: the setting at `default` as it is, and the
/// setting chosen leave-one-flight-out.
pub(crate) fn cross_validate(
    flights: &[Flight],
    grid: &[ReferenceFilter],
    default: usize,
) -> ReferenceOutcome {
    let n = flights.len();
    let identity = UnitQuaternion::identity();
    let first: Vec<Vec<Paired>> = grid
        .iter()
        .map(|&filter| {
            flights
                .iter()
                .map(|f| run_paired(f, &f.fused, filter, &identity).0)
                .collect()
        })
        .collect();
    let chosen: Vec<usize> = (0..n)
        .map(|f| {
            let scores: Vec<f64> = first
                .iter()
                .map(|runs| training_score(&without(runs, f)))
                .collect();
            (0..scores.len())
                .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
                .unwrap_or(default)
        })
        .collect();
    // The units' runs from the airframe's attitude, for each setting that scores a flight.
    let mut singles: Vec<Option<Vec<Vec<Paired>>>> = vec![None; grid.len()];
    for &c in chosen.iter().chain(std::iter::once(&default)) {
        if singles[c].is_none() {
            singles[c] = Some(
                flights
                    .iter()
                    .map(|f| {
                        f.singles
                            .iter()
                            .map(|m| run_paired(f, m, grid[c], &identity).0)
                            .collect()
                    })
                    .collect(),
            );
        }
    }
    let scored = |f: usize, c: usize| {
        let units = singles[c].as_deref().unwrap_or_default();
        score(flights, f, grid[c], &first[c], units)
    };
    let results = (0..n)
        .map(|f| ReferenceFlight {
            default: scored(f, default),
            cross_validated: scored(f, chosen[f]),
        })
        .collect();
    let figures = grid
        .iter()
        .enumerate()
        .map(|(c, filter)| CandidateFigure {
            name: filter.name(),
            in_sample_roll_pitch_rmse_deg: training_score(&first[c].iter().collect::<Vec<_>>()),
            chosen: chosen.iter().filter(|&&x| x == c).count(),
        })
        .collect();
    ReferenceOutcome {
        flights: results,
        grid: figures,
    }
}

/// The naive fusion of the units' own filters on one flight.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct PeerAverageScore {
    /// Roll/pitch RMSE, degrees (null when no row has every unit's attitude).
    pub roll_pitch_rmse_deg: Option<f64>,
    /// The same over the windows of time since the start.
    pub window_rmse_deg: WindowRmse,
}

/// Each flight's average of its units' own attitudes, scored with the mounting fitted on the
/// other flights' averages (those with the same units when there are any).
pub(crate) fn score_peer_average(flights: &[Flight]) -> Vec<PeerAverageScore> {
    let averages: Vec<&Paired> = flights.iter().map(|f| &f.peer_average).collect();
    (0..flights.len())
        .map(|f| {
            if averages[f].is_empty() {
                return PeerAverageScore::default();
            }
            let others: Vec<&Paired> = same_units(flights, &averages, f, None)
                .into_iter()
                .copied()
                .collect();
            let tilt = fit_mounting(&others, SETTLE_S);
            let rmse = roll_pitch_rmse_deg(averages[f], tilt, 0.0);
            PeerAverageScore {
                roll_pitch_rmse_deg: rmse.is_finite().then_some(rmse),
                window_rmse_deg: windows::of(averages[f], tilt),
            }
        })
        .collect()
}

/// Every reference filter's grid figures.
#[derive(Debug, Clone, Default)]
pub struct ReferenceGrids {
    /// Madgwick's settings.
    pub madgwick: Vec<CandidateFigure>,
    /// Mahony's settings.
    pub mahony: Vec<CandidateFigure>,
}

/// The per-flight results with the references filled in, and the grids' figures.
pub(crate) struct WithReferences {
    /// Per flight, in order.
    pub flights: Vec<FlightResult>,
    /// Every reference filter's grid figures.
    pub grids: ReferenceGrids,
}

/// Scores Madgwick's and Mahony's filters and the average of the units' own filters on every
/// flight and adds them to `results` (rins's per-flight results, in the same order).
pub(crate) fn score_all(flights: &[Flight], mut results: Vec<FlightResult>) -> WithReferences {
    let (grid, default) = madgwick_grid();
    let madgwick = cross_validate(flights, &grid, default);
    let (grid, default) = mahony_grid();
    let mahony = cross_validate(flights, &grid, default);
    let averages = score_peer_average(flights);
    for (((result, m), h), a) in results
        .iter_mut()
        .zip(madgwick.flights)
        .zip(mahony.flights)
        .zip(averages)
    {
        result.madgwick = m;
        result.mahony = h;
        result.peer_average = a;
    }
    WithReferences {
        flights: results,
        grids: ReferenceGrids {
            madgwick: madgwick.grid,
            mahony: mahony.grid,
        },
    }
}
