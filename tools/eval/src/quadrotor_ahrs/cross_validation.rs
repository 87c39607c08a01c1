//! Leave-one-flight-out: the candidate and the mountings that score a flight are learnt on the
//! other flights only (see the module docs of [`super`]).

use nalgebra::UnitQuaternion;
use rins_navigator::inertial_core::AidedConfig;

use super::candidates::Candidate;
use super::live::ScoredRun;
use super::mounting::{Paired, fit_mounting, mounting_rotation, roll_pitch_rmse_deg};
use super::run::{AttitudeTrace, GyroPrior, navigate_ahrs};
use super::{CandidateFigure, Flight, FlightResult, SETTLE_S, pair, with_candidate};
use super::{honesty, windows};
use crate::datasets::quadrotor::MAX_IMUS;
use crate::quadrotor_nav::frames::Motion;
use crate::quadrotor_nav::metrics::mean;

/// The per-flight results and the candidates' figures.
pub struct Outcome {
    /// Per flight, in order.
    pub flights: Vec<FlightResult>,
    /// Every candidate's in-sample figure and how often it was chosen.
    pub candidates: Vec<CandidateFigure>,
    /// Per flight, the fused run that scored it, to be repeated by the running service.
    pub runs: Vec<ScoredRun>,
}

/// Mean score of `runs` after [`SETTLE_S`] with the mounting fitted on all of them.
pub(super) fn training_score(runs: &[&Paired]) -> f64 {
    let tilt = fit_mounting(runs, SETTLE_S);
    mean(
        &runs
            .iter()
            .map(|p| roll_pitch_rmse_deg(p, tilt, SETTLE_S))
            .collect::<Vec<_>>(),
    )
}

/// `runs` without flight `f`.
pub(super) fn without<T>(runs: &[T], f: usize) -> Vec<&T> {
    runs.iter()
        .enumerate()
        .filter(|&(g, _)| g != f)
        .map(|(_, r)| r)
        .collect()
}

/// The runs of the flights other than `f` and `also_left_out` that carry the same units as `f` (the
/// fused solution of four units and of one are different instruments, with different biases and
/// mountings); all those flights when none does.
pub(super) fn same_units<'a, T>(
    flights: &[Flight],
    runs: &'a [T],
    f: usize,
    also_left_out: Option<usize>,
) -> Vec<&'a T> {
    let kept = |g: usize| g != f && Some(g) != also_left_out;
    let pick = |same: bool| -> Vec<&T> {
        runs.iter()
            .enumerate()
            .filter(|&(g, _)| kept(g) && (!same || flights[g].imus == flights[f].imus))
            .map(|(_, r)| r)
            .collect()
    };
    let same = pick(true);
    if same.is_empty() { pick(false) } else { same }
}

/// Where unit `imu` sits in each flight other than `f` that has it: `(flight, position)`.
pub(super) fn others_with_unit(flights: &[Flight], f: usize, imu: usize) -> Vec<(usize, usize)> {
    flights
        .iter()
        .enumerate()
        .filter(|&(g, _)| g != f)
        .filter_map(|(g, other)| other.imus.iter().position(|&u| u == imu).map(|k| (g, k)))
        .collect()
}

/// Smallest σ of a gyro bias prior, rad/s (0.05 °/s): a unit's bias moves between flights.
const MIN_PRIOR_SIGMA_RPS: f64 = 0.05 * std::f64::consts::PI / 180.0;

/// One run's attitude at the flight's reference rows, and the gyro bias it ended with.
struct Scored {
    paired: Paired,
    final_gyro_bias_rps: [f64; 3],
}

fn run_paired(
    flight: &Flight,
    motion: &Motion,
    config: &AidedConfig,
    mounting: &UnitQuaternion<f64>,
    prior: Option<&GyroPrior>,
) -> Scored {
    let run = navigate_ahrs(motion, &flight.start, config, mounting, prior);
    Scored {
        paired: pair(&run.trace, flight.start.t_s, &flight.rows),
        final_gyro_bias_rps: run.final_gyro_bias_rps,
    }
}

/// The multiples of the spread tried as the prior's σ (chosen on the other flights).
const PRIOR_SIGMA_SCALES: [f64; 4] = [0.1, 0.25, 0.5, 1.0];

/// The gyro bias the same series ended the other flights with: their mean, σ `scale` times their
/// spread (at least [`MIN_PRIOR_SIGMA_RPS`]). A unit's bias changes little between flights of one
/// session; the live navigator has the same knowledge from its static alignment before take-off.
fn prior_from(others: &[&Scored], scale: f64) -> Option<GyroPrior> {
    let biases: Vec<[f64; 3]> = others.iter().map(|s| s.final_gyro_bias_rps).collect();
    gyro_prior(&biases, scale)
}

/// A gyro bias prior from the biases `final_biases_rps` (rad/s) the same series ended other
/// flights with: their mean, σ `scale` times their largest per-axis spread (at least
/// [`MIN_PRIOR_SIGMA_RPS`]); `None` without any.
pub fn gyro_prior(final_biases_rps: &[[f64; 3]], scale: f64) -> Option<GyroPrior> {
    if final_biases_rps.is_empty() {
        return None;
    }
    let n = final_biases_rps.len() as f64;
    let mut bias = [0.0; 3];
    for b in final_biases_rps {
        for (m, x) in bias.iter_mut().zip(b) {
            *m += x / n;
        }
    }
    let spread = (0..3)
        .map(|axis| {
            let var = final_biases_rps
                .iter()
                .map(|b| (b[axis] - bias[axis]).powi(2))
                .sum::<f64>()
                / n;
            var.sqrt()
        })
        .fold(0.0, f64::max);
    Some(GyroPrior {
        bias_rps: bias,
        sigma_rps: (scale * spread).max(MIN_PRIOR_SIGMA_RPS),
    })
}

fn paired<'a>(runs: &[&'a Scored]) -> Vec<&'a Paired> {
    runs.iter().map(|s| &s.paired).collect()
}

/// Flight `g` of the training set without `f`, scored as a held-out flight of that set: mounting
/// and gyro prior from the first-pass runs of the flights other than `g` and `f`.
fn training_run(
    flights: &[Flight],
    first: &[Scored],
    config: &AidedConfig,
    g: usize,
    f: usize,
    scale: f64,
) -> f64 {
    let others = same_units(flights, first, g, Some(f));
    let tilt = fit_mounting(&paired(&others), SETTLE_S);
    let run = run_paired(
        &flights[g],
        &flights[g].fused,
        config,
        &mounting_rotation(tilt),
        prior_from(&others, scale).as_ref(),
    );
    roll_pitch_rmse_deg(&run.paired, tilt, 0.0)
}

/// The prior σ scale with the best mean score over the flights other than `f`.
fn choose_prior_scale(flights: &[Flight], first: &[Scored], config: &AidedConfig, f: usize) -> f64 {
    let score = |scale: f64| {
        mean(
            &(0..flights.len())
                .filter(|&g| g != f)
                .map(|g| training_run(flights, first, config, g, f, scale))
                .collect::<Vec<_>>(),
        )
    };
    PRIOR_SIGMA_SCALES
        .into_iter()
        .map(|scale| (score(scale), scale))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(1.0, |(_, scale)| scale)
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
    // First pass: every candidate on every flight, started from the airframe's attitude; the
    // runs are independent, so they share the machine's cores.
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    let runs = crate::parallel::run_indexed(
        configs.len() * n,
        threads,
        |k| {
            let flight = &flights[k % n];
            Ok::<_, std::convert::Infallible>(run_paired(
                flight,
                &flight.fused,
                &configs[k / n],
                &identity,
                None,
            ))
        },
        |_, _| progress(1),
    );
    let mut runs = match runs {
        Ok(runs) => runs.into_iter(),
        Err(never) => match never {},
    };
    let first: Vec<Vec<Scored>> = configs
        .iter()
        .map(|_| runs.by_ref().take(n).collect())
        .collect();
    let chosen: Vec<usize> = (0..n)
        .map(|f| {
            let scores: Vec<f64> = first
                .iter()
                .map(|runs| training_score(&paired(&without(runs, f))))
                .collect();
            (0..scores.len())
                .min_by(|&a, &b| scores[a].total_cmp(&scores[b]))
                .unwrap_or(0)
        })
        .collect();
    // First-pass single units for each candidate that was chosen somewhere.
    let mut singles: Vec<Option<Vec<Vec<Scored>>>> = (0..grid.len()).map(|_| None).collect();
    for &c in &chosen {
        if singles[c].is_none() {
            singles[c] = Some(
                flights
                    .iter()
                    .map(|f| {
                        f.singles
                            .iter()
                            .map(|m| run_paired(f, m, &configs[c], &identity, None))
                            .collect()
                    })
                    .collect(),
            );
            progress(n * MAX_IMUS);
        }
    }
    // Each flight's scored runs, and the training runs that choose its prior: independent of
    // the other flights' (the first pass is shared, read-only).
    let scored = crate::parallel::run_indexed(
        n,
        threads,
        |f| {
            let flight = &flights[f];
            let c = chosen[f];
            let config = &configs[c];
            let scale = choose_prior_scale(flights, &first[c], config, f);
            let others = same_units(flights, &first[c], f, None);
            let tilt = fit_mounting(&paired(&others), SETTLE_S);
            let scored = ScoredRun {
                flight: flight.name.clone(),
                motion: flight.fused.clone(),
                start: flight.start,
                config: *config,
                mounting: mounting_rotation(tilt),
                prior: prior_from(&others, scale),
                tilt_rad: tilt,
                rows: flight.rows.clone(),
                trace: AttitudeTrace::default(),
            };
            let trace = scored.rerun(&flight.fused);
            let scored = ScoredRun { trace, ..scored };
            let fused = scored.paired(&scored.trace);
            let mut single = [None; MAX_IMUS];
            let mut peer = [None; MAX_IMUS];
            let mut peer_windows = [None; MAX_IMUS];
            for (k, &imu) in flight.imus.iter().enumerate() {
                let others = others_with_unit(flights, f, imu);
                if others.is_empty() {
                    continue;
                }
                if let Some(runs) = &singles[c] {
                    let same: Vec<&Scored> = others.iter().map(|&(g, j)| &runs[g][j]).collect();
                    let tilt = fit_mounting(&paired(&same), SETTLE_S);
                    let own = run_paired(
                        flight,
                        &flight.singles[k],
                        config,
                        &mounting_rotation(tilt),
                        prior_from(&same, scale).as_ref(),
                    );
                    single[imu - 1] = Some(roll_pitch_rmse_deg(&own.paired, tilt, 0.0));
                }
                let tilt = fit_mounting(
                    &others
                        .iter()
                        .map(|&(g, j)| &flights[g].peers[j])
                        .collect::<Vec<_>>(),
                    SETTLE_S,
                );
                peer[imu - 1] = Some(roll_pitch_rmse_deg(&flight.peers[k], tilt, 0.0));
                peer_windows[imu - 1] = Some(windows::of(&flight.peers[k], tilt));
            }
            let result = FlightResult {
                name: flight.name.clone(),
                imus: flight.imus.clone(),
                rows: flight.rows.len(),
                candidate: format!("{}, bias prior {scale}×spread", grid[c].name),
                fused_roll_pitch_rmse_deg: roll_pitch_rmse_deg(&fused, tilt, 0.0),
                single_roll_pitch_rmse_deg: single,
                peer_roll_pitch_rmse_deg: peer,
                truth_offset_s: flight.truth_offset_s,
                file_offsets_s: flight.file_offsets_s.clone(),
                repairs: flight.repairs,
                notes: flight.notes.clone(),
                fused_window_rmse_deg: windows::of(&fused, tilt),
                fused_error_over_sigma: honesty::error_over_sigma(
                    &fused,
                    tilt,
                    &scored.trace,
                    flight.start.t_s,
                ),
                peer_window_rmse_deg: peer_windows,
                peer_average: Default::default(),
                madgwick: Default::default(),
                mahony: Default::default(),
                live: None,
            };
            Ok::<_, std::convert::Infallible>((result, scored))
        },
        |_, _| progress(MAX_IMUS + 1),
    );
    let (results, runs): (Vec<FlightResult>, Vec<ScoredRun>) = match scored {
        Ok(scored) => scored.into_iter().unzip(),
        Err(never) => match never {},
    };
    let candidates = grid
        .iter()
        .enumerate()
        .map(|(c, candidate)| CandidateFigure {
            name: candidate.name.clone(),
            in_sample_roll_pitch_rmse_deg: training_score(
                &first[c].iter().map(|s| &s.paired).collect::<Vec<_>>(),
            ),
            chosen: chosen.iter().filter(|&&x| x == c).count(),
        })
        .collect();
    Outcome {
        flights: results,
        candidates,
        runs,
    }
}
