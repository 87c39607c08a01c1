//! The `--mode ahrs` summary and its table.

use std::fmt::Write as _;
use std::path::Path;

use super::{AhrsReport, CandidateFigure, FlightResult, MAX_IMUS, ROLL_PITCH_TARGET_DEG};
use crate::datasets::quadrotor::{Repairs, SkippedTrial, skipped_lines};
use crate::quadrotor_nav::metrics::mean;
use crate::quadrotor_nav::report::met;

/// Mean per unit over the flights that have it.
fn per_unit(
    flights: &[FlightResult],
    pick: impl Fn(&FlightResult) -> [Option<f64>; MAX_IMUS],
) -> [Option<f64>; MAX_IMUS] {
    std::array::from_fn(|k| {
        let values: Vec<f64> = flights.iter().filter_map(|f| pick(f)[k]).collect();
        (!values.is_empty()).then(|| mean(&values))
    })
}

/// The report from the per-flight results.
pub fn summarise(
    dir: &Path,
    flights_total: usize,
    repairs: Repairs,
    failures: Vec<SkippedTrial>,
    flights: Vec<FlightResult>,
    candidates: Vec<CandidateFigure>,
) -> AhrsReport {
    let fused = mean(
        &flights
            .iter()
            .map(|f| f.fused_roll_pitch_rmse_deg)
            .collect::<Vec<_>>(),
    );
    let single = per_unit(&flights, |f| f.single_roll_pitch_rmse_deg);
    let peer = per_unit(&flights, |f| f.peer_roll_pitch_rmse_deg);
    let below_all = |values: &[Option<f64>; MAX_IMUS]| {
        values.iter().flatten().all(|&v| fused < v) && values.iter().any(Option::is_some)
    };
    AhrsReport {
        dir: dir.to_path_buf(),
        flights_total,
        flights_evaluated: flights.len(),
        repairs,
        failures,
        roll_pitch_rmse_deg: fused,
        fused_better_than_every_peer: below_all(&peer),
        fused_better_than_every_single: below_all(&single),
        single_roll_pitch_rmse_deg: single,
        peer_roll_pitch_rmse_deg: peer,
        roll_pitch_target_deg: ROLL_PITCH_TARGET_DEG,
        roll_pitch_target_met: fused <= ROLL_PITCH_TARGET_DEG,
        candidates,
        fused_error_over_sigma: super::windows::mean(
            flights.iter().map(|f| &f.fused_error_over_sigma),
        ),
        references: super::reference_report::ReferenceSummary::default(),
        flights,
        live: None,
    }
}

fn cell(v: Option<f64>) -> String {
    v.map_or_else(|| "    -".to_string(), |x| format!("{x:5.2}"))
}

/// The [`cell`]s of one RMSE per unit, side by side.
fn cells(v: &[Option<f64>]) -> String {
    v.iter().map(|v| cell(*v)).collect::<Vec<_>>().join(" ")
}

/// The human-readable table.
pub fn to_table(r: &AhrsReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "AHRS roll/pitch RMSE, degrees, leave-one-flight-out ({} of {} flights evaluated)",
        r.flights_evaluated, r.flights_total
    );
    let _ = writeln!(
        s,
        "{:22} {:>6} | {:>5} {:>5} {:>5} {:>5} | {:>5} {:>5} {:>5} {:>5} | {:>7}  candidate",
        "flight",
        "fused",
        "rins1",
        "rins2",
        "rins3",
        "rins4",
        "peer1",
        "peer2",
        "peer3",
        "peer4",
        "gt off"
    );
    for f in &r.flights {
        let _ = writeln!(
            s,
            "{:22} {:6.2} | {} | {} | {:+7.3}  {}",
            f.name,
            f.fused_roll_pitch_rmse_deg,
            cells(&f.single_roll_pitch_rmse_deg),
            cells(&f.peer_roll_pitch_rmse_deg),
            f.truth_offset_s,
            f.candidate
        );
    }
    let _ = writeln!(
        s,
        "{:22} {:6.2} | {} | {} |",
        "mean",
        r.roll_pitch_rmse_deg,
        cells(&r.single_roll_pitch_rmse_deg),
        cells(&r.peer_roll_pitch_rmse_deg)
    );
    let _ = writeln!(
        s,
        "fused better than every unit's own filter: {}; than every unit alone: {}; target {:.2}°: {}",
        r.fused_better_than_every_peer,
        r.fused_better_than_every_single,
        r.roll_pitch_target_deg,
        met(r.roll_pitch_target_met)
    );
    let _ = writeln!(
        s,
        "tilt settings: first pass (gyro bias learnt from zero), mean over every flight after the first {} s with the mounting fitted on all (shown, not used to choose); flights it was chosen for:",
        super::SETTLE_S
    );
    for c in &r.candidates {
        let _ = writeln!(
            s,
            "  {:32} {:6.2}  {}",
            c.name, c.in_sample_roll_pitch_rmse_deg, c.chosen
        );
    }
    let [first, rest] = r.fused_error_over_sigma.map(cell);
    let _ = writeln!(
        s,
        "fused tilt error over the filter's own σ, RMS over flights (1: the σ is right): first {} s {first}, after {rest}",
        super::SETTLE_S
    );
    super::reference_report::lines(&mut s, r);
    let p = &r.repairs;
    let _ = writeln!(
        s,
        "repairs: counter wraps {}, repeated timestamps {}, samples filled {}, non-finite rows {}, rows dropped {}, unit files skipped {}, flights failed {}",
        p.counter_wraps,
        p.repeated_timestamps,
        p.missing_samples_filled,
        p.non_finite_rows,
        p.rows_dropped,
        p.imu_files_skipped,
        p.trials_failed
    );
    if let Some(live) = &r.live {
        live_lines(&mut s, r, live);
    }
    s.push_str(&skipped_lines(&r.failures));
    s
}

/// The fused runs through the running processes, per flight and over all.
fn live_lines(s: &mut String, r: &AhrsReport, live: &super::live::LiveSummary) {
    let _ = writeln!(
        s,
        "through the running processes ({}): roll/pitch RMSE, largest attitude difference to the \
         in-process run, to the pipeline's code in process on the same frames, and what fusion \
         made of the input in process, degrees",
        live.live_input
    );
    for f in &r.flights {
        if let Some(l) = &f.live {
            let _ = writeln!(
                s,
                "{:22} {:6.2} | {:9.2e} {:9.2e} {:9.2e} | fusion events {:5}, excluded: {}",
                f.name,
                l.live_roll_pitch_rmse_deg,
                l.live_vs_offline_max_diff_deg,
                l.live_vs_same_input_max_diff_deg,
                l.quantisation_max_diff_deg,
                l.live_fdi_events,
                if l.live_excluded_channels.is_empty() {
                    "none".to_string()
                } else {
                    l.live_excluded_channels.join(", ")
                }
            );
        }
    }
    let _ = writeln!(
        s,
        "{:22} {:6.2} | {:9.2e} {:9.2e} {:9.2e} | flights with a channel excluded: {}; rows missing: {}",
        "live",
        live.live_roll_pitch_rmse_deg,
        live.live_vs_offline_max_diff_deg,
        live.live_vs_same_input_max_diff_deg,
        live.quantisation_max_diff_deg,
        live.flights_with_live_exclusions,
        live.live_rows_missing
    );
}
