//! The GNSS modes' report as text.

use std::fmt::Write;

use super::{GnssMode, GnssReport, OUTAGE_RATIO_TARGET, OUTAGE_S, ROLL_PITCH_TARGET_DEG};
use crate::trial_rows::unit_then_fused_rows;

/// One line per run, then the means and the targets.
pub fn to_table(r: &GnssReport) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "{:<22} {:>6} {:<6} {:>9} {:>9} {:>9} {:>10} {:>8}",
        "flight", "s", "run", "rp rmse°", "yaw rmse°", "horiz m", "end err m", "rejected"
    );
    for t in &r.trials {
        for (name, secs, run) in unit_then_fused_rows(&t.name, t.duration_s, &t.single, &t.fused) {
            let label = run.imu.map_or("fused".to_string(), |i| format!("imu{i}"));
            let _ = writeln!(
                s,
                "{name:<22} {secs:>6} {label:<6} {:>9.3} {:>9.2} {:>9.2} {:>10.2} {:>8}",
                run.roll_pitch_rmse_deg,
                run.heading_rmse_deg,
                run.horizontal_rmse_m,
                run.end_horizontal_error_m,
                run.rejections
            );
        }
    }
    let _ = writeln!(
        s,
        "fused, mean over {} flights: roll/pitch {:.3}° (target {ROLL_PITCH_TARGET_DEG}°: {}), heading {:.2}°, horizontal {:.2} m; receiver rejections on clean fixes (drift test chosen leave-one-flight-out): {} in all runs, {} in the fused ones",
        r.trials.len(),
        r.roll_pitch_rmse_deg,
        if r.roll_pitch_target_met {
            "met"
        } else {
            "not met"
        },
        r.heading_rmse_deg,
        r.horizontal_rmse_m,
        r.gnss_rejections,
        r.gnss_rejections_fused
    );
    let _ = writeln!(
        s,
        "fused roll/pitch with the units' mounting tilt fitted as --mode ahrs fits it: {:.3}° (fitted on the other flights), {:.3}° (in sample, fitted on every flight)",
        r.roll_pitch_rmse_mounted_deg, r.roll_pitch_rmse_mounted_in_sample_deg
    );
    let windows: Vec<String> = r
        .window_starts_s
        .iter()
        .zip(&r.fused_window_rmse_deg)
        .map(|(from, v)| match v {
            Some(v) => format!("from {from} s {v:.3}°"),
            None => format!("from {from} s -"),
        })
        .collect();
    let _ = writeln!(
        s,
        "the same by time since the start: {}",
        windows.join(", ")
    );
    let _ = writeln!(
        s,
        "the reference against itself and the units, tilt per axis over 1 s: its attitude change against the gyros {:.3}°, its positions against its attitude and the accelerometers {:.3}° (no filter following the gyros or the positions gets closer to it)",
        r.reference_attitude_vs_gyro_deg, r.reference_position_vs_attitude_deg
    );
    if let Some(a) = &r.antenna_in_sample {
        let [x, y, z] = a.lever_arm_m;
        let _ = writeln!(
            s,
            "antenna fitted on every flight (each flight runs with the fit of the others): lever arm [{x:.3}, {y:.3}, {z:.3}] m, position lead {:.1} ms",
            a.position_lead_s * 1e3
        );
    }
    if r.mode == GnssMode::Outage {
        let singles: Vec<String> = r
            .single_outage_error_m
            .iter()
            .map(|e| format!("{e:.2}"))
            .collect();
        let _ = writeln!(
            s,
            "after a {OUTAGE_S} s outage: fused {:.2} m, single units [{}] m, median single {:.2} m; fused/median {:.2} (target {OUTAGE_RATIO_TARGET}: {})",
            r.outage_error_m,
            singles.join(", "),
            r.median_single_outage_error_m,
            r.outage_ratio,
            if r.outage_target_met {
                "met"
            } else {
                "not met"
            }
        );
    }
    for skip in &r.skipped {
        let _ = writeln!(s, "skipped {}: {}", skip.trial, skip.reason);
    }
    s
}
