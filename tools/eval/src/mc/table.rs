//! The comparison report as Markdown tables (for docs/fault-tolerance.md): the fault-free errors with their
//! ratios beside the published ones, then the kill experiment.

use std::fmt::Write;

use super::report::{KillStats, McReport, PUBLISHED_CLAIMS, WindowStats};
use crate::stats::Stat;

/// The statistic of a window that one row of the kill table shows.
type StatOf = fn(&WindowStats) -> Stat;

impl McReport {
    /// The comparison as Markdown tables (for docs/fault-tolerance.md): the fault-free errors with their
    /// ratios beside the published ones, then the kill experiment.
    pub fn to_table(&self) -> String {
        let mut s = String::new();
        let (r, o) = (&self.redundant, &self.orthogonal);
        let _ = writeln!(
            s,
            "Monte Carlo, {} runs (seeds {}..={}), {} s of the {} scenario at {} Hz; same per-channel \
             error model and seeds for both blocks.\n",
            self.runs,
            self.first_seed,
            self.first_seed
                .wrapping_add(self.runs.saturating_sub(1) as u64),
            num(self.duration_s),
            scenario_name(self.scenario),
            num(self.imu_rate_hz),
        );
        let _ = writeln!(
            s,
            "Gyro bias: {}. Fault-free flights with a channel flagged or left out of the solution (false alarm): \
             {} for {} s on average, {} for {} s.\n",
            if self.gyro_channels_calibrated_at_rest {
                "per channel in the fuser, from the static alignment window"
            } else {
                "on the fused body axes by the navigator's static alignment"
            },
            r.label,
            num(r.nominal.degraded_s.mean),
            o.label,
            num(o.nominal.degraded_s.mean),
        );
        let _ = writeln!(
            s,
            "Noise amplification per axis x/y/z, √diag((HᵀH)⁻¹): {} {}; {} {}.\n",
            r.label,
            triple(r.noise_amplification),
            o.label,
            triple(o.noise_amplification),
        );
        let (a, b) = (&r.label, &o.label);
        header(
            &mut s,
            &[
                "error",
                &format!("{a} final"),
                &format!("{b} final"),
                "ratio of 2σ",
                &format!("{a} RMS over flight"),
                &format!("{b} RMS over flight"),
                "ratio of means",
                "[R1], 5 h: redundant / orthogonal = ratio",
            ],
        );
        let (rf, of) = (&r.nominal.final_errors, &o.nominal.final_errors);
        let (rr, or) = (&r.nominal.rms, &o.nominal.rms);
        let (fr, mr) = (&self.final_two_sigma_ratio, &self.rms_mean_ratio);
        let rows = [
            (
                "roll/pitch, ° (per axis)",
                rf.roll_pitch_deg,
                of.roll_pitch_deg,
                fr.roll_pitch,
                rr.roll_pitch_deg,
                or.roll_pitch_deg,
                mr.roll_pitch,
                &PUBLISHED_CLAIMS[0],
            ),
            (
                "heading, °",
                rf.heading_deg,
                of.heading_deg,
                fr.heading,
                rr.heading_deg,
                or.heading_deg,
                mr.heading,
                &PUBLISHED_CLAIMS[1],
            ),
            (
                "horizontal position, m (final per axis N/E; RMS of length)",
                rf.horizontal_per_axis_m,
                of.horizontal_per_axis_m,
                fr.horizontal,
                rr.horizontal_m,
                or.horizontal_m,
                mr.horizontal,
                &PUBLISHED_CLAIMS[2],
            ),
            (
                "altitude (baro-aided), m",
                rf.altitude_m,
                of.altitude_m,
                fr.altitude,
                rr.altitude_m,
                or.altitude_m,
                mr.altitude,
                &PUBLISHED_CLAIMS[3],
            ),
        ];
        for (name, a, b, ratio, ra, rb, rms_ratio, published) in rows {
            let _ = writeln!(
                s,
                "| {name} | {} | {} | {} | {} | {} | {} | ±{} / ±{} = {} |",
                pm(&a),
                pm(&b),
                num(ratio),
                pm(&ra),
                pm(&rb),
                num(rms_ratio),
                num(published.redundant),
                num(published.orthogonal),
                num(published.ratio),
            );
        }
        let _ = writeln!(
            s,
            "\nCells are mean ± 2σ over runs. \"final\": signed error at the end of the flight (roll and \
             pitch pooled, north and east pooled). \"RMS over flight\": per run, the RMS from alignment to \
             the end, sampled at 100 Hz; roll/pitch per axis, horizontal as the error length. The published \
             experiment [R1] flew 5 h with its own aiding: compare ratios, not absolute values."
        );
        if let (Some(rk), Some(ok)) = (&r.kill, &o.kill) {
            self.kill_table(&mut s, rk, ok);
        }
        s
    }

    /// The kill experiment's table and its notes, appended to `s`.
    fn kill_table(&self, s: &mut String, rk: &KillStats, ok: &KillStats) {
        let (r, o) = (&self.redundant, &self.orthogonal);
        let after =
            |x: Option<[f64; 3]>| x.map_or("no solution (fewer than 3 axes)".into(), triple);
        let _ = writeln!(
            s,
            "\nGyro channel {} dead from {} s to the end ({} s). Noise amplification after the kill: {} {}; {} {}.\n",
            rk.channel,
            num(rk.at_s),
            num(self.duration_s - rk.at_s),
            r.label,
            after(r.noise_amplification_after_kill),
            o.label,
            after(o.noise_amplification_after_kill),
        );
        let (a, b) = (&r.label, &o.label);
        header(
            s,
            &[
                "after the kill",
                &format!("{a}, no fault"),
                &format!("{a}, channel dead"),
                &format!("{b}, no fault"),
                &format!("{b}, channel dead"),
            ],
        );
        let cols = [&rk.nominal, &rk.faulted, &ok.nominal, &ok.faulted];
        let row = |s: &mut String, name: &str, cell: &dyn Fn(&WindowStats) -> String| {
            let cells: Vec<String> = cols.iter().map(|w| cell(w)).collect();
            let _ = writeln!(s, "| {name} | {} |", cells.join(" | "));
        };
        row(s, "time without solution, s (mean, max)", &|w| {
            format!("{} (max {})", num(w.unsolved_s.mean), num(w.unsolved_s.max))
        });
        row(s, "time with a channel left out, s (mean)", &|w| {
            num(w.degraded_s.mean)
        });
        row(s, "runs navigating at the end", &|w| {
            format!("{} of {}", w.runs_solved_at_end, w.runs)
        });
        // The error rows: "lost" where no run was navigating at the end.
        let errors: [(&str, StatOf); 7] = [
            ("final roll/pitch, °", |w| w.final_errors.roll_pitch_deg),
            ("final heading, °", |w| w.final_errors.heading_deg),
            ("final horizontal (per axis), m", |w| {
                w.final_errors.horizontal_per_axis_m
            }),
            ("final altitude, m", |w| w.final_errors.altitude_m),
            ("RMS roll/pitch after the kill, °", |w| {
                w.rms.roll_pitch_deg
            }),
            ("RMS heading after the kill, °", |w| w.rms.heading_deg),
            ("RMS horizontal after the kill, m", |w| w.rms.horizontal_m),
        ];
        for (name, stat) in errors {
            row(s, name, &|w| {
                let stat = stat(w);
                if w.runs_solved_at_end == 0 || stat.n == 0 {
                    "lost".to_string()
                } else {
                    pm(&stat)
                }
            });
        }
        let jump = |k: &KillStats| {
            let j = k.reconfiguration_jump_deg;
            if j.n == 0 {
                "no solution".to_string()
            } else {
                format!("{} (max {})", num(j.mean), num(j.max))
            }
        };
        let _ = writeln!(
            s,
            "\nReconfiguration: attitude difference to the no-fault flight over the first {} s after \
             the kill, ° (mean, max over runs): {} {}; {} {}.",
            num(super::run::JUMP_WINDOW_S),
            r.label,
            jump(rk),
            o.label,
            jump(ok),
        );
        let _ = writeln!(
            s,
            "\n\"lost\": the fuser reports too few gyro channels, the navigator cannot integrate and \
             there is no solution to compare; the RMS of a dead run covers only the ticks that still \
             had one."
        );
    }
}

/// A Markdown table's header row of `columns` and the rule under it.
fn header(s: &mut String, columns: &[&str]) {
    let _ = writeln!(s, "| {} |", columns.join(" | "));
    let _ = writeln!(s, "|{}", "---|".repeat(columns.len()));
}

/// A number with about three significant digits.
fn num(x: f64) -> String {
    if !x.is_finite() {
        return "–".into();
    }
    let a = x.abs();
    if a == 0.0 {
        "0".into()
    } else if a >= 100.0 {
        format!("{x:.0}")
    } else if a >= 10.0 {
        format!("{x:.1}")
    } else if a >= 1.0 {
        format!("{x:.2}")
    } else if a >= 0.01 {
        format!("{x:.3}")
    } else {
        format!("{x:.1e}")
    }
}

/// `mean ± 2σ`, or a dash without samples.
fn pm(s: &Stat) -> String {
    if s.n == 0 {
        return "–".into();
    }
    format!("{} ± {}", num(s.mean), num(s.two_sigma))
}

/// Three numbers as `x/y/z`.
fn triple(x: [f64; 3]) -> String {
    format!("{}/{}/{}", num(x[0]), num(x[1]), num(x[2]))
}

/// The scenario as the command line names it.
fn scenario_name(scenario: rins_sim::Scenario) -> &'static str {
    match scenario {
        rins_sim::Scenario::Static => "static",
        rins_sim::Scenario::Uav => "uav",
        rins_sim::Scenario::Walk => "walk",
        rins_sim::Scenario::Calibrate => "calibrate",
        rins_sim::Scenario::Multirotor => "multirotor",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_keep_three_significant_digits() {
        assert_eq!(num(1234.4), "1234");
        assert_eq!(num(12.345), "12.3");
        assert_eq!(num(1.2345), "1.23");
        assert_eq!(num(0.012345), "0.012");
        assert_eq!(num(0.0012345), "1.2e-3");
        assert_eq!(num(f64::NAN), "–");
    }
}
