//! Text tables of the foot-mounted evaluations.

use std::fmt::Write;

use super::live::LiveWalkSummary;
use super::{FootMethod, PyshoeReport, Skipped, XioReport};
use crate::integrity_tally::IntegritySummary;

fn opt(v: Option<f64>) -> String {
    v.map_or_else(|| "-".into(), |x| format!("{x:.3}"))
}

fn method_name(m: FootMethod) -> &'static str {
    match m {
        FootMethod::Rins => "rins",
        FootMethod::Reference => "the peer's method (SHOE + ZUPT EKF, one threshold)",
    }
}

fn integrity(i: &Option<IntegritySummary>) -> String {
    i.as_ref().map_or_else(
        || "-".into(),
        |i| format!("{:.1}% {}", 100.0 * i.ok_fraction, i.reasons),
    )
}

fn skipped(s: &mut String, list: &[Skipped]) {
    for k in list {
        let _ = writeln!(s, "skipped {}: {}", k.file, k.reason);
    }
}

/// The pyshoe evaluation as a text table: one line per trial, then the means on both metrics.
pub fn pyshoe_table(r: &PyshoeReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "evaluated: {} (ARMSE: the peer's metric; thresholds chosen leave-one-trial-out)\n",
        method_name(r.method)
    );
    let _ = writeln!(
        s,
        "{:<20} {:>5} {:>7} {:>7} {:>7} {:>7} {:>7} {:>5} {:>7} {:>7} {:>6} {:>6}  integrity",
        "trial",
        "s",
        "rmse2d",
        "ARMSE",
        "peer",
        "p.shoe",
        "ref",
        "beat",
        "stride",
        "mov.st",
        "on ms",
        "end ms"
    );
    for t in &r.trials {
        let _ = writeln!(
            s,
            "{:<20} {:>5.1} {:>7.3} {:>7.3} {:>7} {:>7} {:>7.3} {:>5} {:>7.3} {:>6.0}% {:>6.0} {:>6.0}  {}",
            t.trial,
            t.seconds,
            t.rmse_2d_m,
            t.armse_m,
            opt(t.peer_armse_m),
            opt(t.peer_shoe_armse_m),
            t.reference_armse_m,
            match t.better_than_peer {
                Some(true) => "yes",
                Some(false) => "no",
                None => "-",
            },
            t.strides.length_ratio,
            100.0 * t.strides.stance_while_moving,
            1e3 * t.strides.onset_delay_s,
            1e3 * t.strides.end_delay_s,
            integrity(&t.integrity)
        );
    }
    skipped(&mut s, &r.skipped);
    let _ = writeln!(
        s,
        "\nover {} trials: our RMSE {:.3} m; ARMSE {:.3} m against the peer's tuned-per-trial {} m \
         (its SHOE alone {} m); better than the peer on {} of {}",
        r.trials.len(),
        r.mean_rmse_m,
        r.mean_armse_m,
        opt(r.peer_mean_armse_m),
        opt(r.peer_shoe_mean_armse_m),
        r.trials_better_than_peer,
        r.trials_compared
    );
    for d in &r.detectors {
        let _ = writeln!(
            s,
            "detector {:<10} ARMSE {:.3} m held out, better than the peer on {} (chosen on all: \
             threshold {:.3e}, gait exponent {}, raised ×{})",
            d.detector.name(),
            d.mean_armse_m,
            d.trials_better_than_peer,
            d.threshold_all,
            d.gait_exponent_all,
            d.raise_factor_all
        );
    }
    if let (Some(mean), Some(better)) =
        (r.smoothed_mean_armse_m, r.smoothed_trials_better_than_peer)
    {
        let _ = writeln!(
            s,
            "smoothed after the fact (rins, held-out settings): ARMSE {mean:.3} m; better than the \
             peer on {better} of {}",
            r.trials_compared
        );
    }
    let _ = writeln!(
        s,
        "ARMSE by estimator: rins {:.3} m (profile as configured {:.3} m; threshold chosen on all \
         trials {:.3e}, raised ×{} after a second without stance, gait exponent {}), the peer's \
         method with one threshold {:.3} m (chosen on all trials {:.3e})",
        r.rins_mean_armse_m,
        r.rins_profile_mean_armse_m,
        r.rins_threshold_all,
        r.rins_raise_factor_all,
        r.rins_gait_exponent_all,
        r.reference_mean_armse_m,
        r.reference_threshold_all
    );
    let _ = writeln!(
        s,
        "strides: estimated / true length {:.3} on average (stride = foot-down to foot-down)",
        r.mean_stride_length_ratio
    );
    if let Some(live) = &r.live {
        live_table(&mut s, r, live);
    }
    s
}

/// The held-out rins runs through the running processes, beside the in-process figures.
fn live_table(s: &mut String, r: &PyshoeReport, live: &LiveWalkSummary) {
    let _ = writeln!(
        s,
        "
through the running processes ({}), rins held-out setting:",
        live.live_input
    );
    let _ = writeln!(
        s,
        "{:<20} {:>8} {:>8} {:>8} {:>8} {:>10} {:>10} {:>10} {:>6} {:>5}",
        "trial",
        "rmse2d",
        "live",
        "ARMSE",
        "live",
        "vs off mm",
        "vs same mm",
        "quant mm",
        "align",
        "miss"
    );
    for t in &r.trials {
        let Some(l) = &t.live else { continue };
        let _ = writeln!(
            s,
            "{:<20} {:>8.4} {:>8.4} {:>8.4} {:>8.4} {:>10.4} {:>10.4} {:>10.4} {:>6} {:>5}",
            t.trial,
            l.offline_rmse_m,
            l.live_rmse_m,
            l.offline_armse_m,
            l.live_armse_m,
            1e3 * l.live_vs_offline_max_diff_m,
            1e3 * l.live_vs_same_input_max_diff_m,
            1e3 * l.quantisation_max_diff_m,
            l.live_alignment_offset_samples,
            l.live_samples_missing
        );
    }
    let _ = writeln!(
        s,
        "live: RMSE {:.4} m, ARMSE {:.4} m on average; largest difference to the in-process runs \
         {:.4} mm (to the same pipeline in process on the same frames {:.4} mm; the counts and \
         fusion in process {:.4} mm); {} samples missing; {} walks with a channel excluded",
        live.live_mean_rmse_m,
        live.live_mean_armse_m,
        1e3 * live.live_vs_offline_max_diff_m,
        1e3 * live.live_vs_same_input_max_diff_m,
        1e3 * live.quantisation_max_diff_m,
        live.live_samples_missing,
        live.walks_with_live_exclusions
    );
}

/// The x-io evaluation as a text table: one line per walk with its end-point error.
pub fn xio_table(r: &XioReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "evaluated: {}\n", method_name(r.method));
    let _ = writeln!(
        s,
        "{:<14} {:>7} {:>10} {:>11} {:>10} {:>9} {:>8} {:>8}  integrity",
        "walk", "s", "end err m", "distance m", "% dist", "peer m", "stance", "dup rows"
    );
    for t in &r.trials {
        let _ = writeln!(
            s,
            "{:<14} {:>7.1} {:>10.3} {:>11.1} {:>9.2}% {:>9} {:>7.0}% {:>8}  {}",
            t.trial,
            t.seconds,
            t.end_error_m,
            t.distance_m,
            t.pct_distance,
            opt(t.peer_end_error_m),
            100.0 * t.stance_fraction,
            t.dropped_duplicate_rows,
            integrity(&t.integrity)
        );
    }
    for t in &r.trials {
        if let (Some(e), Some(p)) = (t.smoothed_end_error_m, t.smoothed_pct_distance) {
            let _ = writeln!(
                s,
                "{}: smoothed after the fact {e:.3} m ({p:.2}% of the distance)",
                t.trial
            );
        }
    }
    skipped(&mut s, &r.skipped);
    s
}
