//! `errors.png`: the attitude error per axis and the horizontal and vertical position error
//! against truth, with the filter's own 3σ bounds; without truth, the bounds alone.

use std::path::Path;

use super::{BOUND, ERROR, Labels, Line, canvas, fail, note, panel, time_range};
use crate::compare::{
    attitude_error_deg, attitude_three_sigma_deg, position_error_m, position_three_sigma_m,
};
use crate::extract::Extracted;

/// The error series of one quantity: (time, error) where truth matches, (time, 3σ) everywhere.
struct Errors {
    error: Vec<(f64, f64)>,
    bound: Vec<(f64, f64)>,
}

/// Draws the errors of `data` into `path`.
pub fn draw(path: &Path, data: &Extracted) -> Result<(), String> {
    let has_truth = !data.truth.is_empty();
    let matched = data
        .nav
        .iter()
        .filter(|p| data.truth_by_seq.contains_key(&p.seq))
        .count();
    let title = if !has_truth {
        "Errors: the filter's 3σ bounds only (no truth in this file)".to_string()
    } else if matched == 0 {
        "Errors: the filter's 3σ bounds only (no truth sample matches a solution)".to_string()
    } else {
        format!("Errors against truth, with the filter's 3σ bounds ({matched} matched samples)")
    };
    let root = canvas(path, &title)?;
    // Attitude north/east/down, horizontal, vertical.
    let mut series: Vec<Errors> = (0..5)
        .map(|_| Errors {
            error: Vec::new(),
            bound: Vec::with_capacity(data.nav.len()),
        })
        .collect();
    for p in &data.nav {
        let att_bound = attitude_three_sigma_deg(&p.covariance_diag);
        let pos_bound = position_three_sigma_m(&p.covariance_diag);
        for (s, b) in series.iter_mut().zip(att_bound.iter().chain(&pos_bound)) {
            s.bound.push((p.t_s, *b));
        }
        if let Some(t) = data
            .truth_by_seq
            .get(&p.seq)
            .and_then(|&i| data.truth.get(i))
        {
            let att = attitude_error_deg(p.quaternion, t.quaternion);
            let pos = position_error_m(p.ned_m, t.ned_m);
            for (s, e) in series.iter_mut().zip(att.iter().chain(&pos)) {
                s.error.push((p.t_s, *e));
            }
        }
    }
    let x = time_range(data.nav.iter().map(|p| p.t_s));
    let names = [
        ("attitude error about north", "error (deg)", true),
        ("attitude error about east", "error (deg)", true),
        ("attitude error about down", "error (deg)", true),
        ("horizontal position error", "error (m)", false),
        ("vertical position error (down)", "error (m)", true),
    ];
    let areas = root.split_evenly((3, 2));
    // Column-major: the attitude on the left, the position on the right.
    let order = [0, 2, 4, 1, 3, 5];
    for (k, ((caption, unit, symmetric), s)) in names.iter().zip(&series).enumerate() {
        let mut lines = Vec::new();
        if !s.error.is_empty() {
            lines.push(Line::solid("estimate − truth", ERROR, s.error.clone()));
        }
        lines.push(Line::dashed("±3σ (filter)", BOUND, s.bound.clone()));
        if *symmetric {
            lines.push(Line::dashed(
                "",
                BOUND,
                s.bound.iter().map(|&(t, b)| (t, -b)).collect(),
            ));
        } else if let Some(l) = lines.last_mut() {
            l.label = "3σ (filter)".to_string();
        }
        let labels = Labels {
            caption,
            x: "time (s)",
            y: unit,
        };
        panel(&areas[order[k]], labels, &lines, Some(x))?;
    }
    if !has_truth {
        note(
            &areas[order[5]],
            "No truth in this file: only the filter's own bounds are drawn.",
        )?;
    }
    root.present().map_err(fail)
}
