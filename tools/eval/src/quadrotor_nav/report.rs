//! Text table of the quadrotor evaluation.

use std::fmt::Write;

use super::QuadrotorReport;
use super::metrics::Scores;
use crate::datasets::quadrotor::skipped_lines;
use crate::trial_rows::unit_then_fused_rows;

fn label(s: &Scores) -> String {
    s.imu.map_or_else(|| "fused".into(), |k| format!("IMU_{k}"))
}

/// One line per run (each unit, then the fused units) of every trial, then the summary.
pub fn to_table(r: &QuadrotorReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<20} {:>6} {:<6} {:>8} {:>8} {:>10} {:>10} {:>10}",
        "trial", "s", "run", "roll°", "pitch°", "rp rmse°", "height m", "|h| max m"
    );
    for t in &r.trials {
        for (name, seconds, run) in unit_then_fused_rows(&t.name, t.duration_s, &t.single, &t.fused)
        {
            let _ = writeln!(
                s,
                "{:<20} {:>6} {:<6} {:>8.2} {:>8.2} {:>10.2} {:>10.2} {:>10.2}",
                name,
                seconds,
                label(run),
                run.roll_rmse_deg,
                run.pitch_rmse_deg,
                run.roll_pitch_rmse_deg,
                run.height_error_m,
                run.height_error_max_m
            );
        }
        let _ = writeln!(
            s,
            "{:<20} {:>6} {:<6} {:>8} {:>8} {:>10.2}   fused {}",
            "",
            "",
            "median",
            "",
            "",
            t.median_single_roll_pitch_rmse_deg,
            if t.fused_better_than_median_single {
                "better"
            } else {
                "not better"
            }
        );
        let files: Vec<String> = t
            .unit_truth_offsets_s
            .iter()
            .map(|o| format!("{o:+.3}"))
            .collect();
        let _ = writeln!(
            s,
            "{:<20} {:>6} truth clock {:+.3} s (files: {} s){}",
            "",
            "",
            t.truth_offset_s,
            files.join(", "),
            if t.repairs.is_clean() {
                String::new()
            } else {
                format!("; repaired: {}", t.repairs.phrases().join(", "))
            }
        );
    }
    let _ = writeln!(
        s,
        "\nroll/pitch RMSE, mean over {} trials: fused {:.2}°, median single unit {:.2}° \
         (fused better: {}; in {} of {} trials)",
        r.trials.len(),
        r.roll_pitch_rmse_deg,
        r.median_single_roll_pitch_rmse_deg,
        if r.fused_better_than_median_single {
            "yes"
        } else {
            "no"
        },
        r.trials_fused_better,
        r.trials.len()
    );
    let _ = writeln!(
        s,
        "target ≤ {:.1}°: {}",
        r.roll_pitch_target_deg,
        met(r.roll_pitch_target_met)
    );
    let _ = writeln!(
        s,
        "height error at the end (free inertial, no baro), mean |error|: fused {:.1} m, median \
         single unit {:.1} m; largest fused |error| in flight {:.1} m",
        r.fused_height_error_abs_mean_m,
        r.median_single_height_error_abs_mean_m,
        r.fused_height_error_max_m
    );
    let _ = writeln!(
        s,
        "gravity at latitude {:.3}° (profile origin); gyro bias {}",
        r.gravity_latitude_deg, r.gyro_bias
    );
    s.push_str(&skipped_lines(&r.skipped));
    s
}

/// How a target reads in a table.
pub fn met(met: bool) -> &'static str {
    if met { "met" } else { "not met" }
}
