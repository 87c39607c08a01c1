//! Leave-one-flight-out: the candidate and the mountings that score a flight are learnt on the
//! other flights only (see the module docs of [`super`]).

use nalgebra::UnitQuaternion;
use rins_navigator::inertial_core::AidedConfig;

use super::candidates::Candidate;
use super::mounting::{Paired, fit_mounting, mounting_rotation, roll_pitch_rmse_deg};
use super::run::navigate_ahrs;
use super::{CandidateFigure, Flight, FlightResult, SETTLE_S, pair, with_candidate};
use crate::datasets::quadrotor::MAX_IMUS;
use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::metrics::mean;

/// The per-flight results and the candidates' figures.
pub struct Outcome {
    /// Per flight, in order.
    pub flights: Vec<FlightResult>,
    /// Every candidate's in-sample figure and how often it was chosen.
    pub candidates: Vec<CandidateFigure>,
}

/// Mean score of `runs` after [`SETTLE_S`] with the mounting fitted on all of them.
fn training_score(runs: &[&Paired]) -> f64 {
    let tilt = fit_mounting(runs, SETTLE_S);
    mean(
        &runs
            .iter()
            .map(|p| roll_pitch_rmse_deg(p, tilt, SETTLE_S))
            .collect::<Vec<_>>(),
    )
}

/// `runs` without flight `f`.
fn without<T>(runs: &[T], f: usize) -> Vec<&T> {
    runs.iter()
        .enumerate()
        .filter(|&(g, _)| g != f)
        .map(|(_, r)| r)
        .collect()
}

/// Where unit `imu` sits in each flight other than `f` that has it: `(flight, position)`.
fn others_with_unit(flights: &[Flight], f: usize, imu: usize) -> Vec<(usize, usize)> {
    flights
        .iter()
        .enumerate()
        .filter(|&(g, _)| g != f)
        .filter_map(|(g, other)| other.imus.iter().position(|&u| u == imu).map(|k| (g, k)))
        .collect()
}

/// One run's attitude at the flight's reference rows.
fn run_paired(
    flight: &Flight,
    motion: &Motion,
    config: &AidedConfig,
    mounting: &UnitQuaternion<f64>,
) -> Paired {
    let trace = navigate_ahrs(motion, &flight.start, config, mounting);
    pair(&trace, flight.start.t_s, &flight.rows)
}

/// Runs the cross-validation; `progress(runs)` after each batch of navigator runs.
pub(crate) fn run(
    flights: &[Flight],
    grid: &[Candidate],
    base: &AidedConfig,
    progress: &mut dyn FnMut(usize),
) -> Outcome {
    let n = flights.len();
    let identity = UnitQuaternion::identity();
    let configs: Vec<AidedConfig> = grid.iter().map(|c| with_candidate(base, c)).collect();
    // First pass: every candidate on every flight, started from the airframe's attitude.
    let first: Vec<Vec<Paired>> = configs
        .iter()
        .map(|config| {
            let runs = flights
                .iter()
                .map(|f| run_paired(f, &f.fused, config, &identity))
                .collect();
            progress(n);
            runs
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
                .unwrap_or(0)
        })
        .collect();
    // First-pass single units for each candidate that was chosen somewhere.
    let mut singles: Vec<Option<Vec<Vec<Paired>>>> = vec![None; grid.len()];
    for &c in &chosen {
        if singles[c].is_none() {
            singles[c] = Some(
                flights
                    .iter()
                    .map(|f| {
                        f.singles
                            .iter()
                            .map(|m| run_paired(f, m, &configs[c], &identity))
                            .collect()
                    })
                    .collect(),
            );
            progress(n * MAX_IMUS);
        }
    }
    let results = flights
        .iter()
        .enumerate()
        .map(|(f, flight)| {
            let c = chosen[f];
            let config = &configs[c];
            let tilt = fit_mounting(&without(&first[c], f), SETTLE_S);
            let fused = run_paired(flight, &flight.fused, config, &mounting_rotation(tilt));
            let mut single = [None; MAX_IMUS];
            let mut peer = [None; MAX_IMUS];
            for (k, &imu) in flight.imus.iter().enumerate() {
                let others = others_with_unit(flights, f, imu);
                if others.is_empty() {
                    continue;
                }
                if let Some(runs) = &singles[c] {
                    let tilt = fit_mounting(
                        &others.iter().map(|&(g, j)| &runs[g][j]).collect::<Vec<_>>(),
                        SETTLE_S,
                    );
                    let own =
                        run_paired(flight, &flight.singles[k], config, &mounting_rotation(tilt));
                    single[imu - 1] = Some(roll_pitch_rmse_deg(&own, tilt, 0.0));
                }
                let tilt = fit_mounting(
                    &others
                        .iter()
                        .map(|&(g, j)| &flights[g].peers[j])
                        .collect::<Vec<_>>(),
                    SETTLE_S,
                );
                peer[imu - 1] = Some(roll_pitch_rmse_deg(&flight.peers[k], tilt, 0.0));
            }
            progress(MAX_IMUS + 1);
            FlightResult {
                name: flight.name.clone(),
                imus: flight.imus.clone(),
                rows: flight.rows.len(),
                candidate: grid[c].name.clone(),
                fused_roll_pitch_rmse_deg: roll_pitch_rmse_deg(&fused, tilt, 0.0),
                single_roll_pitch_rmse_deg: single,
                peer_roll_pitch_rmse_deg: peer,
                truth_offset_s: flight.truth_offset_s,
                file_offsets_s: flight.file_offsets_s.clone(),
                repairs: flight.repairs,
                notes: flight.notes.clone(),
            }
        })
        .collect();
    let candidates = grid
        .iter()
        .enumerate()
        .map(|(c, candidate)| CandidateFigure {
            name: candidate.name.clone(),
            in_sample_roll_pitch_rmse_deg: training_score(&first[c].iter().collect::<Vec<_>>()),
            chosen: chosen.iter().filter(|&&x| x == c).count(),
        })
        .collect();
    Outcome {
        flights: results,
        candidates,
    }
}
