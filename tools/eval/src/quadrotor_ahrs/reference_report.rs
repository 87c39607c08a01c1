//! The reference filters' and the start windows' summary, and their lines in the `--mode ahrs`
//! table.

use std::fmt::Write as _;

use serde::Serialize;

use super::reference_cv::{ReferenceFlight, ReferenceGrids, ReferenceScore};
use super::windows::{self, WINDOW_STARTS_S, WindowRmse};
use super::{AhrsReport, CandidateFigure, FlightResult, MAX_IMUS};
use crate::quadrotor_nav::metrics::mean;

/// One way of setting a reference filter, over every flight.
#[derive(Debug, Clone, Default, Serialize)]
pub struct SettingSummary {
    /// The setting, or `chosen per flight` for the cross-validated choice.
    pub setting: String,
    /// Mean over flights of the fused roll/pitch RMSE, degrees.
    pub fused_roll_pitch_rmse_deg: f64,
    /// Per unit: mean over the flights that have it of its RMSE alone, degrees.
    pub single_roll_pitch_rmse_deg: [Option<f64>; MAX_IMUS],
    /// Per window: mean over the flights with rows in it of the fused RMSE, degrees.
    pub fused_window_rmse_deg: WindowRmse,
    /// Samples of the scored runs with a zero specific force, all flights.
    pub samples_without_force: usize,
}

/// One reference filter over every flight.
#[derive(Debug, Clone, Default, Serialize)]
pub struct FilterSummary {
    /// The default setting.
    pub default: SettingSummary,
    /// The setting chosen on the other flights, flight by flight.
    pub cross_validated: SettingSummary,
    /// Every setting's in-sample figure (fused, first pass, mounting fitted on every flight after
    /// the settling time) and how often it was chosen.
    pub grid: Vec<CandidateFigure>,
}

/// The windows' means over the flights that reach the last window, so that the windows compare
/// the same flights.
#[derive(Debug, Clone, Default, Serialize)]
pub struct LongFlightWindows {
    /// Flights with rows in every window.
    pub flights: usize,
    /// rins fused, per window, degrees.
    pub fused_window_rmse_deg: WindowRmse,
    /// Each unit's own filter per window, by unit number.
    pub peer_window_rmse_deg: [Option<WindowRmse>; MAX_IMUS],
    /// The average of the units' own filters per window.
    pub peer_average_window_rmse_deg: WindowRmse,
    /// Madgwick's default, fused, per window.
    pub madgwick_default_window_rmse_deg: WindowRmse,
    /// Madgwick cross-validated, fused, per window.
    pub madgwick_cross_validated_window_rmse_deg: WindowRmse,
    /// Mahony's default, fused, per window.
    pub mahony_default_window_rmse_deg: WindowRmse,
    /// Mahony cross-validated, fused, per window.
    pub mahony_cross_validated_window_rmse_deg: WindowRmse,
}

/// Each unit's windows, mean over `flights` that have the unit.
fn peer_windows(flights: &[&FlightResult]) -> [Option<WindowRmse>; MAX_IMUS] {
    std::array::from_fn(|k| {
        let present: Vec<&WindowRmse> = flights
            .iter()
            .filter_map(|f| f.peer_window_rmse_deg[k].as_ref())
            .collect();
        (!present.is_empty()).then(|| windows::mean(present))
    })
}

fn long_flight_windows(flights: &[FlightResult]) -> LongFlightWindows {
    let long: Vec<&FlightResult> = flights
        .iter()
        .filter(|f| f.fused_window_rmse_deg.iter().all(Option::is_some))
        .collect();
    let of = |pick: fn(&FlightResult) -> &WindowRmse| windows::mean(long.iter().map(|f| pick(f)));
    LongFlightWindows {
        flights: long.len(),
        fused_window_rmse_deg: of(|f| &f.fused_window_rmse_deg),
        peer_window_rmse_deg: peer_windows(&long),
        peer_average_window_rmse_deg: of(|f| &f.peer_average.window_rmse_deg),
        madgwick_default_window_rmse_deg: of(|f| &f.madgwick.default.fused_window_rmse_deg),
        madgwick_cross_validated_window_rmse_deg: of(|f| {
            &f.madgwick.cross_validated.fused_window_rmse_deg
        }),
        mahony_default_window_rmse_deg: of(|f| &f.mahony.default.fused_window_rmse_deg),
        mahony_cross_validated_window_rmse_deg: of(|f| {
            &f.mahony.cross_validated.fused_window_rmse_deg
        }),
    }
}

/// The references and the start analysis, over every flight.
#[derive(Debug, Clone, Default, Serialize)]
pub struct ReferenceSummary {
    /// Where the windows of time since the start begin, s: `[a, b)`, `[b, c)`, `[c, end)`.
    pub window_starts_s: [f64; 3],
    /// Flights with rows in each window (a flight shorter than a window's start has none).
    pub flights_per_window: [usize; 3],
    /// rins fused, per window: mean over the flights with rows in it, degrees.
    pub fused_window_rmse_deg: WindowRmse,
    /// Each unit's own filter per window, by unit number.
    pub peer_window_rmse_deg: [Option<WindowRmse>; MAX_IMUS],
    /// The average of the units' own filters: mean over flights of its RMSE, degrees.
    pub peer_average_roll_pitch_rmse_deg: Option<f64>,
    /// The same per window.
    pub peer_average_window_rmse_deg: WindowRmse,
    /// The windows over the flights that reach every window.
    pub long_flight_windows: LongFlightWindows,
    /// Madgwick's filter.
    pub madgwick: FilterSummary,
    /// Mahony's filter.
    pub mahony: FilterSummary,
}

/// Mean of the values present; `None` when none is.
fn mean_of(values: impl Iterator<Item = Option<f64>>) -> Option<f64> {
    let v: Vec<f64> = values.flatten().collect();
    (!v.is_empty()).then(|| mean(&v))
}

fn setting(
    flights: &[FlightResult],
    name: String,
    pick: impl Fn(&FlightResult) -> &ReferenceScore,
) -> SettingSummary {
    SettingSummary {
        setting: name,
        fused_roll_pitch_rmse_deg: mean(
            &flights
                .iter()
                .map(|f| pick(f).fused_roll_pitch_rmse_deg)
                .collect::<Vec<_>>(),
        ),
        single_roll_pitch_rmse_deg: std::array::from_fn(|k| {
            mean_of(
                flights
                    .iter()
                    .map(|f| pick(f).single_roll_pitch_rmse_deg[k]),
            )
        }),
        fused_window_rmse_deg: windows::mean(
            flights.iter().map(|f| &pick(f).fused_window_rmse_deg),
        ),
        samples_without_force: flights.iter().map(|f| pick(f).samples_without_force).sum(),
    }
}

fn filter(
    flights: &[FlightResult],
    grid: Vec<CandidateFigure>,
    pick: impl Fn(&FlightResult) -> &ReferenceFlight,
) -> FilterSummary {
    let default_name = flights
        .first()
        .map(|f| pick(f).default.setting.clone())
        .unwrap_or_default();
    FilterSummary {
        default: setting(flights, default_name, |f| &pick(f).default),
        cross_validated: setting(flights, "chosen per flight".to_string(), |f| {
            &pick(f).cross_validated
        }),
        grid,
    }
}

/// The summary from the per-flight results.
pub fn summarise(flights: &[FlightResult], grids: ReferenceGrids) -> ReferenceSummary {
    ReferenceSummary {
        window_starts_s: WINDOW_STARTS_S,
        flights_per_window: std::array::from_fn(|w| {
            flights
                .iter()
                .filter(|f| f.fused_window_rmse_deg[w].is_some())
                .count()
        }),
        fused_window_rmse_deg: windows::mean(flights.iter().map(|f| &f.fused_window_rmse_deg)),
        peer_window_rmse_deg: peer_windows(&flights.iter().collect::<Vec<_>>()),
        peer_average_roll_pitch_rmse_deg: mean_of(
            flights.iter().map(|f| f.peer_average.roll_pitch_rmse_deg),
        ),
        peer_average_window_rmse_deg: windows::mean(
            flights.iter().map(|f| &f.peer_average.window_rmse_deg),
        ),
        long_flight_windows: long_flight_windows(flights),
        madgwick: filter(flights, grids.madgwick, |f| &f.madgwick),
        mahony: filter(flights, grids.mahony, |f| &f.mahony),
    }
}

fn cell(v: Option<f64>) -> String {
    v.map_or_else(|| "     -".to_string(), |x| format!("{x:6.2}"))
}

fn cells(v: &[Option<f64>]) -> String {
    v.iter().map(|v| cell(*v)).collect::<Vec<_>>().join(" ")
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

/// The references' and the start analysis's lines of the table.
pub fn lines(s: &mut String, r: &AhrsReport) {
    let x = &r.references;
    let (m, h) = (&x.madgwick, &x.mahony);
    let _ = writeln!(
        s,
        "reference filters on the same motion, scored the same way (mounting fitted on the other flights); roll/pitch RMSE, degrees, mean over flights:"
    );
    let _ = writeln!(
        s,
        "  {:34} {:>6} | {:>6} {:>6} {:>6} {:>6}",
        "series", "fused", "unit1", "unit2", "unit3", "unit4"
    );
    let mut row = |name: &str, fused: Option<f64>, units: &[Option<f64>; MAX_IMUS]| {
        let _ = writeln!(s, "  {name:34} {} | {}", cell(fused), cells(units));
    };
    row(
        "rins (cross-validated)",
        finite(r.roll_pitch_rmse_deg),
        &r.single_roll_pitch_rmse_deg,
    );
    row("units' own filters", None, &r.peer_roll_pitch_rmse_deg);
    row(
        "units' own filters averaged",
        x.peer_average_roll_pitch_rmse_deg,
        &[None; MAX_IMUS],
    );
    for (label, summary) in [
        (format!("{} (default)", m.default.setting), &m.default),
        ("Madgwick cross-validated".to_string(), &m.cross_validated),
        (format!("{} (default)", h.default.setting), &h.default),
        ("Mahony cross-validated".to_string(), &h.cross_validated),
    ] {
        row(
            &label,
            finite(summary.fused_roll_pitch_rmse_deg),
            &summary.single_roll_pitch_rmse_deg,
        );
    }
    let _ = writeln!(
        s,
        "  per flight, fused: {:20} {:>6} {:>6} | {:>6} {:>6} | {:>6} {:>6}  chosen",
        "", "rins", "avg", "M dflt", "M cv", "H dflt", "H cv"
    );
    for f in &r.flights {
        let _ = writeln!(
            s,
            "  {:39} {} {} | {} {} | {} {}  {}; {}",
            f.name,
            cell(finite(f.fused_roll_pitch_rmse_deg)),
            cell(f.peer_average.roll_pitch_rmse_deg),
            cell(finite(f.madgwick.default.fused_roll_pitch_rmse_deg)),
            cell(finite(f.madgwick.cross_validated.fused_roll_pitch_rmse_deg)),
            cell(finite(f.mahony.default.fused_roll_pitch_rmse_deg)),
            cell(finite(f.mahony.cross_validated.fused_roll_pitch_rmse_deg)),
            f.madgwick.cross_validated.setting,
            f.mahony.cross_validated.setting
        );
    }
    let _ = writeln!(
        s,
        "  reference settings in sample (fused, first pass, mean over every flight after the first {} s with the mounting fitted on all; shown, not used to choose); flights chosen for:",
        super::SETTLE_S
    );
    for c in m.grid.iter().chain(&h.grid) {
        let _ = writeln!(
            s,
            "    {:30} {:6.2}  {}",
            c.name, c.in_sample_roll_pitch_rmse_deg, c.chosen
        );
    }
    let without_force = m.default.samples_without_force
        + m.cross_validated.samples_without_force
        + h.default.samples_without_force
        + h.cross_validated.samples_without_force;
    let _ = writeln!(
        s,
        "  samples with a zero specific force (rate integrated only): {without_force}"
    );
    window_lines(s, r);
}

/// The start analysis: RMSE per window of time since the start, mean over the flights with rows
/// in the window, then over the flights that reach every window.
fn window_lines(s: &mut String, r: &AhrsReport) {
    let x = &r.references;
    let long = &x.long_flight_windows;
    let [a, b, c] = x.window_starts_s;
    let _ = writeln!(
        s,
        "roll/pitch RMSE by time since the start, degrees: mean over the flights with rows in the window ({} / {} / {} flights), and over the {} flights that reach every window:",
        x.flights_per_window[0], x.flights_per_window[1], x.flights_per_window[2], long.flights
    );
    let heads = [
        format!("[{a},{b})"),
        format!("[{b},{c})"),
        format!("[{c},end)"),
    ];
    let _ = writeln!(
        s,
        "  {:34} {:>9} {:>9} {:>9} | {:>6} || {:>9} {:>9} {:>9}",
        "series", heads[0], heads[1], heads[2], "whole", heads[0], heads[1], heads[2]
    );
    let mut row = |name: &str, w: &WindowRmse, whole: Option<f64>, l: &WindowRmse| {
        let _ = writeln!(
            s,
            "  {name:34} {:>9} {:>9} {:>9} | {} || {:>9} {:>9} {:>9}",
            cell(w[0]),
            cell(w[1]),
            cell(w[2]),
            cell(whole),
            cell(l[0]),
            cell(l[1]),
            cell(l[2])
        );
    };
    row(
        "rins fused",
        &x.fused_window_rmse_deg,
        finite(r.roll_pitch_rmse_deg),
        &long.fused_window_rmse_deg,
    );
    for k in 0..MAX_IMUS {
        if let Some(w) = &x.peer_window_rmse_deg[k] {
            row(
                &format!("unit {}'s own filter", k + 1),
                w,
                r.peer_roll_pitch_rmse_deg[k],
                &long.peer_window_rmse_deg[k].unwrap_or([None; 3]),
            );
        }
    }
    row(
        "units' own filters averaged",
        &x.peer_average_window_rmse_deg,
        x.peer_average_roll_pitch_rmse_deg,
        &long.peer_average_window_rmse_deg,
    );
    for (label, summary, l) in [
        (
            "Madgwick default, fused",
            &x.madgwick.default,
            &long.madgwick_default_window_rmse_deg,
        ),
        (
            "Madgwick cross-validated, fused",
            &x.madgwick.cross_validated,
            &long.madgwick_cross_validated_window_rmse_deg,
        ),
        (
            "Mahony default, fused",
            &x.mahony.default,
            &long.mahony_default_window_rmse_deg,
        ),
        (
            "Mahony cross-validated, fused",
            &x.mahony.cross_validated,
            &long.mahony_cross_validated_window_rmse_deg,
        ),
    ] {
        row(
            label,
            &summary.fused_window_rmse_deg,
            finite(summary.fused_roll_pitch_rmse_deg),
            l,
        );
    }
}
