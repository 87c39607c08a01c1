//! Text tables of the foot-mounted evaluations.

use std::fmt::Write;

use super::{PyshoeReport, XioReport};

fn opt(v: Option<f64>, scale: f64) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{:.3}", x * scale))
}

/// The pyshoe evaluation as a text table: one line per trial, then the mean 2-D RMSE beside the
/// peer's.
pub fn pyshoe_table(r: &PyshoeReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<22} {:>7} {:>10} {:>14} {:>9} {:>8} {:>9} {:>6}  integrity reasons",
        "trial", "s", "rmse2d m", "peer(tuned) m", "heading°", "stance", "zupt rej", "ok"
    );
    for t in &r.trials {
        let _ = writeln!(
            s,
            "{:<22} {:>7.1} {:>10.3} {:>14} {:>9.1} {:>7.0}% {:>9} {:>5.1}%  {}",
            t.trial,
            t.seconds,
            t.rmse_2d_m,
            opt(t.peer_rmse_2d_m, 1.0),
            t.heading_fit_deg,
            100.0 * t.stance_fraction,
            t.zupt_rejected,
            100.0 * t.integrity.ok_fraction,
            t.integrity.reasons
        );
    }
    let _ = writeln!(
        s,
        "\nmean 2-D RMSE: {:.3} m over {} trials (peer, threshold tuned per trial: {})",
        r.mean_rmse_m,
        r.trials.len(),
        opt(r.peer_mean_rmse_m, 1.0)
    );
    s
}

/// The x-io evaluation as a text table: one line per walk with its end-point error.
pub fn xio_table(r: &XioReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<14} {:>7} {:>10} {:>11} {:>10} {:>9} {:>8} {:>8} {:>6}  integrity reasons",
        "walk", "s", "end err m", "distance m", "% dist", "peer m", "stance", "dup rows", "ok"
    );
    for t in &r.trials {
        let _ = writeln!(
            s,
            "{:<14} {:>7.1} {:>10.3} {:>11.1} {:>9.2}% {:>9} {:>7.0}% {:>8} {:>5.1}%  {}",
            t.trial,
            t.seconds,
            t.end_error_m,
            t.distance_m,
            t.pct_distance,
            opt(t.peer_end_error_m, 1.0),
            100.0 * t.stance_fraction,
            t.dropped_duplicate_rows,
            100.0 * t.integrity.ok_fraction,
            t.integrity.reasons
        );
    }
    s
}
