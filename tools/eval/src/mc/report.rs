//! Aggregation of the runs into the comparison report, and its Markdown rendering.

use std::fmt::Write;

use serde::Serialize;

use super::config::Prepared;
use super::errors::WindowResult;
use super::run::{RunRecord, SystemRun};
use crate::stats::Stat;

/// Statistics over runs of the errors at the end of a window. Signed quantities: the mean shows a
/// common bias, the 2σ the spread between runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FinalStats {
    /// Roll and pitch errors pooled (two samples per run), degrees.
    pub roll_pitch_deg: Stat,
    /// Heading error, degrees.
    pub heading_deg: Stat,
    /// North and east position errors pooled (two samples per run), m.
    pub horizontal_per_axis_m: Stat,
    /// Length of the horizontal position error, m.
    pub horizontal_m: Stat,
    /// Altitude error, m.
    pub altitude_m: Stat,
}

/// Statistics over runs of the per-run RMS over the window (see
/// [`super::errors::RmsErrors`] for each quantity).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RmsStats {
    /// Per-axis roll/pitch RMS, degrees.
    pub roll_pitch_deg: Stat,
    /// Heading RMS, degrees.
    pub heading_deg: Stat,
    /// RMS of the horizontal error length, m.
    pub horizontal_m: Stat,
    /// Altitude RMS, m.
    pub altitude_m: Stat,
}

/// One window (e.g. alignment → end) of one system over all runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WindowStats {
    /// Runs that had this window.
    pub runs: usize,
    /// Runs with a navigation solution at the end of the window (the final errors are over these).
    pub runs_solved_at_end: usize,
    /// Errors at the end of the window.
    pub final_errors: FinalStats,
    /// RMS over the window (runs with at least one solution in it).
    pub rms: RmsStats,
    /// Time without a valid solution inside the window, s.
    pub unsolved_s: Stat,
    /// Time with some channel left out of the solution inside the window, s.
    pub degraded_s: Stat,
}

/// The fault experiment of one system.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct KillStats {
    /// Gyro channel killed.
    pub channel: usize,
    /// Kill time, s.
    pub at_s: f64,
    /// Fault-free flight, kill time → end (same seeds): the baseline.
    pub nominal: WindowStats,
    /// Flight with the channel dead, kill time → end.
    pub faulted: WindowStats,
    /// Runs whose faulted flight had no solution at the end: navigation lost.
    pub lost_runs: usize,
    /// Attitude difference to the no-fault flight over the first second after the kill, ° (over
    /// the runs that had both solutions).
    pub reconfiguration_jump_deg: Stat,
}

/// One system over all runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SystemReport {
    /// Name of the block.
    pub label: String,
    /// Gyro (and accelerometer) channels.
    pub channels: usize,
    /// Per-axis noise amplification √diag((HᵀH)⁻¹) of the full channel set.
    pub noise_amplification: [f64; 3],
    /// Same with the killed channel removed; `None` when the rest cannot solve 3 axes.
    pub noise_amplification_after_kill: Option<[f64; 3]>,
    /// Runs whose alignment completed.
    pub aligned_runs: usize,
    /// Fault-free flight from alignment to the end.
    pub nominal: WindowStats,
    /// The fault experiment, when it ran.
    pub kill: Option<KillStats>,
}

/// Redundant ÷ orthogonal for each error.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ratios {
    pub roll_pitch: f64,
    pub heading: f64,
    pub horizontal: f64,
    pub altitude: f64,
}

/// A seed-003 claim (DESIGN §4.5): 2σ after a 5 h simulated UAV flight with its own aiding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeedClaim {
    pub quantity: &'static str,
    pub unit: &'static str,
    /// Redundant skewed block, 2σ.
    pub redundant: f64,
    /// Orthogonal block with the same sensors, 2σ.
    pub orthogonal: f64,
    /// redundant ÷ orthogonal.
    pub ratio: f64,
}

const fn claim(
    quantity: &'static str,
    unit: &'static str,
    redundant: f64,
    orthogonal: f64,
) -> SeedClaim {
    SeedClaim {
        quantity,
        unit,
        redundant,
        orthogonal,
        ratio: redundant / orthogonal,
    }
}

/// The seed-003 table: roll/pitch, heading (÷ cos φ), position, baro altitude.
pub const SEED_003_CLAIMS: [SeedClaim; 4] = [
    claim("roll/pitch", "°", 0.22, 0.38),
    claim("heading (× cos φ)", "°", 0.3, 0.45),
    claim("position", "m", 600.0, 1400.0),
    claim("baro altitude", "m", 1.3, 2.1),
];

/// The comparison. Runs are deterministic per seed, so equal configurations give equal reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct McReport {
    pub runs: usize,
    pub first_seed: u64,
    /// Simulated flight time, s.
    pub duration_s: f64,
    pub imu_rate_hz: f64,
    /// Kill time, s, when the fault experiment ran.
    pub kill_at_s: Option<f64>,
    /// Gyro channel biases calibrated in the fuser from the static window (see
    /// [`super::McConfig::calibrate_gyro_channels_at_rest`]).
    pub gyro_channels_calibrated_at_rest: bool,
    pub redundant: SystemReport,
    pub orthogonal: SystemReport,
    /// Redundant ÷ orthogonal of the 2σ of the final errors (roll/pitch and position per axis).
    pub final_two_sigma_ratio: Ratios,
    /// Redundant ÷ orthogonal of the mean over runs of the RMS over the flight.
    pub rms_mean_ratio: Ratios,
    /// The seed's claims, for the ratio: its absolute numbers come from a 5 h flight with other
    /// aiding and are not comparable with these.
    pub seed_003: [SeedClaim; 4],
    /// Every run, for plots and checks.
    pub records: Vec<RunRecord>,
}

fn window_stats(windows: &[WindowResult]) -> WindowStats {
    let finals: Vec<_> = windows.iter().filter_map(|w| w.final_errors).collect();
    let rms: Vec<_> = windows.iter().filter_map(|w| w.rms).collect();
    let pooled = |f: &dyn Fn(&super::errors::NavErrors) -> [f64; 2]| {
        Stat::of(&finals.iter().flat_map(f).collect::<Vec<_>>())
    };
    let single = |f: &dyn Fn(&super::errors::NavErrors) -> f64| {
        Stat::of(&finals.iter().map(f).collect::<Vec<_>>())
    };
    let over_rms = |f: &dyn Fn(&super::errors::RmsErrors) -> f64| {
        Stat::of(&rms.iter().map(f).collect::<Vec<_>>())
    };
    WindowStats {
        runs: windows.len(),
        runs_solved_at_end: finals.len(),
        final_errors: FinalStats {
            roll_pitch_deg: pooled(&|e| [e.roll_deg, e.pitch_deg]),
            heading_deg: single(&|e| e.heading_deg),
            horizontal_per_axis_m: pooled(&|e| [e.north_m, e.east_m]),
            horizontal_m: single(&|e| e.horizontal_m()),
            altitude_m: single(&|e| e.altitude_m),
        },
        rms: RmsStats {
            roll_pitch_deg: over_rms(&|r| r.roll_pitch_deg),
            heading_deg: over_rms(&|r| r.heading_deg),
            horizontal_m: over_rms(&|r| r.horizontal_m),
            altitude_m: over_rms(&|r| r.altitude_m),
        },
        unsolved_s: Stat::of(&windows.iter().map(|w| w.unsolved_s).collect::<Vec<_>>()),
        degraded_s: Stat::of(&windows.iter().map(|w| w.degraded_s).collect::<Vec<_>>()),
    }
}

fn noise_amplification(factors: [f64; 3]) -> [f64; 3] {
    factors.map(f64::sqrt)
}

fn system_report(
    prepared: &Prepared,
    index: usize,
    runs: &[&SystemRun],
    kill_at_s: Option<f64>,
) -> SystemReport {
    let system = &prepared.systems[index];
    let axes = system.geometry.axes();
    let remaining: Vec<[f64; 3]> = axes
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != prepared.kill_channel)
        .map(|(_, a)| *a)
        .collect();
    let after_kill = rins_fusion::Geometry::from_axes(&remaining)
        .ok()
        .map(|g| noise_amplification(g.variance_factors()));
    let nominal: Vec<_> = runs.iter().filter_map(|r| r.nominal).collect();
    let kills: Vec<_> = runs.iter().filter_map(|r| r.kill).collect();
    let kill = kill_at_s.filter(|_| !kills.is_empty()).map(|at_s| {
        let faulted: Vec<_> = kills.iter().map(|k| k.faulted).collect();
        KillStats {
            channel: prepared.kill_channel,
            at_s,
            nominal: window_stats(&kills.iter().map(|k| k.nominal).collect::<Vec<_>>()),
            faulted: window_stats(&faulted),
            lost_runs: faulted.iter().filter(|w| w.final_errors.is_none()).count(),
            reconfiguration_jump_deg: Stat::of(
                &kills
                    .iter()
                    .filter_map(|k| k.reconfiguration_jump_deg)
                    .collect::<Vec<_>>(),
            ),
        }
    });
    SystemReport {
        label: system.label.clone(),
        channels: system.geometry.n(),
        noise_amplification: noise_amplification(system.geometry.variance_factors()),
        noise_amplification_after_kill: after_kill,
        aligned_runs: runs.iter().filter(|r| r.aligned_at_s.is_some()).count(),
        nominal: window_stats(&nominal),
        kill,
    }
}

impl McReport {
    pub(crate) fn new(prepared: &Prepared, first_seed: u64, records: Vec<RunRecord>) -> Self {
        let kill_at_s = prepared
            .kill_tick
            .map(|k| k as f64 / prepared.sim.imu_rate_hz);
        let redundant_runs: Vec<_> = records.iter().map(|r| &r.redundant).collect();
        let orthogonal_runs: Vec<_> = records.iter().map(|r| &r.orthogonal).collect();
        let redundant = system_report(prepared, 0, &redundant_runs, kill_at_s);
        let orthogonal = system_report(prepared, 1, &orthogonal_runs, kill_at_s);
        let (r, o) = (&redundant.nominal, &orthogonal.nominal);
        let final_two_sigma_ratio = Ratios {
            roll_pitch: r.final_errors.roll_pitch_deg.two_sigma
                / o.final_errors.roll_pitch_deg.two_sigma,
            heading: r.final_errors.heading_deg.two_sigma / o.final_errors.heading_deg.two_sigma,
            horizontal: r.final_errors.horizontal_per_axis_m.two_sigma
                / o.final_errors.horizontal_per_axis_m.two_sigma,
            altitude: r.final_errors.altitude_m.two_sigma / o.final_errors.altitude_m.two_sigma,
        };
        let rms_mean_ratio = Ratios {
            roll_pitch: r.rms.roll_pitch_deg.mean / o.rms.roll_pitch_deg.mean,
            heading: r.rms.heading_deg.mean / o.rms.heading_deg.mean,
            horizontal: r.rms.horizontal_m.mean / o.rms.horizontal_m.mean,
            altitude: r.rms.altitude_m.mean / o.rms.altitude_m.mean,
        };
        Self {
            runs: records.len(),
            first_seed,
            duration_s: prepared.duration_s,
            imu_rate_hz: prepared.sim.imu_rate_hz,
            kill_at_s,
            gyro_channels_calibrated_at_rest: prepared.gyro_channel_bias_ticks.is_some(),
            redundant,
            orthogonal,
            final_two_sigma_ratio,
            rms_mean_ratio,
            seed_003: SEED_003_CLAIMS,
            records,
        }
    }

    /// The comparison as Markdown tables (for the README): the fault-free errors with their
    /// ratios beside the seed's, then the kill experiment.
    pub fn to_table(&self) -> String {
        let mut s = String::new();
        let (r, o) = (&self.redundant, &self.orthogonal);
        let _ = writeln!(
            s,
            "Monte Carlo, {} runs (seeds {}..={}), {} s of the UAV profile at {} Hz; same per-channel \
             error model and seeds for both blocks.\n",
            self.runs,
            self.first_seed,
            self.first_seed
                .wrapping_add(self.runs.saturating_sub(1) as u64),
            num(self.duration_s),
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
        let _ = writeln!(
            s,
            "| error | {a} final | {b} final | ratio of 2σ | {a} RMS over flight | {b} RMS over flight | ratio of means | seed 003, 5 h: redundant / orthogonal = ratio |",
            a = r.label,
            b = o.label
        );
        let _ = writeln!(s, "|---|---|---|---|---|---|---|---|");
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
                &SEED_003_CLAIMS[0],
            ),
            (
                "heading, °",
                rf.heading_deg,
                of.heading_deg,
                fr.heading,
                rr.heading_deg,
                or.heading_deg,
                mr.heading,
                &SEED_003_CLAIMS[1],
            ),
            (
                "horizontal position, m (final per axis N/E; RMS of length)",
                rf.horizontal_per_axis_m,
                of.horizontal_per_axis_m,
                fr.horizontal,
                rr.horizontal_m,
                or.horizontal_m,
                mr.horizontal,
                &SEED_003_CLAIMS[2],
            ),
            (
                "altitude (baro-aided), m",
                rf.altitude_m,
                of.altitude_m,
                fr.altitude,
                rr.altitude_m,
                or.altitude_m,
                mr.altitude,
                &SEED_003_CLAIMS[3],
            ),
        ];
        for (name, a, b, ratio, ra, rb, rms_ratio, seed) in rows {
            let _ = writeln!(
                s,
                "| {name} | {} | {} | {} | {} | {} | {} | ±{} / ±{} = {} |",
                pm(&a),
                pm(&b),
                num(ratio),
                pm(&ra),
                pm(&rb),
                num(rms_ratio),
                num(seed.redundant),
                num(seed.orthogonal),
                num(seed.ratio),
            );
        }
        let _ = writeln!(
            s,
            "\nCells are mean ± 2σ over runs. \"final\": signed error at the end of the flight (roll and \
             pitch pooled, north and east pooled). \"RMS over flight\": per run, the RMS from alignment to \
             the end, sampled at 100 Hz; roll/pitch per axis, horizontal as the error length. Seed 003 \
             flew 5 h with its own aiding: compare ratios, not absolute values."
        );
        if let (Some(rk), Some(ok)) = (&r.kill, &o.kill) {
            self.kill_table(&mut s, rk, ok);
        }
        s
    }

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
        let _ = writeln!(
            s,
            "| after the kill | {a}, no fault | {a}, channel dead | {b}, no fault | {b}, channel dead |",
            a = r.label,
            b = o.label
        );
        let _ = writeln!(s, "|---|---|---|---|---|");
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
        let lost_or = |w: &WindowStats, stat: Stat| {
            if w.runs_solved_at_end == 0 || stat.n == 0 {
                "lost".to_string()
            } else {
                pm(&stat)
            }
        };
        row(s, "final roll/pitch, °", &|w| {
            lost_or(w, w.final_errors.roll_pitch_deg)
        });
        row(s, "final heading, °", &|w| {
            lost_or(w, w.final_errors.heading_deg)
        });
        row(s, "final horizontal (per axis), m", &|w| {
            lost_or(w, w.final_errors.horizontal_per_axis_m)
        });
        row(s, "final altitude, m", &|w| {
            lost_or(w, w.final_errors.altitude_m)
        });
        row(s, "RMS roll/pitch after the kill, °", &|w| {
            lost_or(w, w.rms.roll_pitch_deg)
        });
        row(s, "RMS heading after the kill, °", &|w| {
            lost_or(w, w.rms.heading_deg)
        });
        row(s, "RMS horizontal after the kill, m", &|w| {
            lost_or(w, w.rms.horizontal_m)
        });
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

fn pm(s: &Stat) -> String {
    if s.n == 0 {
        return "–".into();
    }
    format!("{} ± {}", num(s.mean), num(s.two_sigma))
}

fn triple(x: [f64; 3]) -> String {
    format!("{}/{}/{}", num(x[0]), num(x[1]), num(x[2]))
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

    #[test]
    fn seed_ratios() {
        assert!((SEED_003_CLAIMS[2].ratio - 600.0 / 1400.0).abs() < 1e-15);
        assert!((SEED_003_CLAIMS[0].ratio - 0.22 / 0.38).abs() < 1e-15);
    }
}
