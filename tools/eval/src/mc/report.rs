//! Aggregation of the runs into the comparison report: statistics over runs per system and window,
//! the fault experiment, and the ratios of the redundant block to the orthogonal one. The report's
//! Markdown rendering is in [`super::table`].

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
    /// Roll and pitch.
    pub roll_pitch: f64,
    /// Heading.
    pub heading: f64,
    /// Horizontal position.
    pub horizontal: f64,
    /// Altitude.
    pub altitude: f64,
}

/// A published figure of the redundant-versus-orthogonal comparison this experiment repeats (the
/// structural-redundancy paper, \[R1\] in docs/references.md): 2σ after a 5 h simulated UAV flight with
/// that paper's own aiding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PublishedClaim {
    /// The error compared.
    pub quantity: &'static str,
    /// Its unit.
    pub unit: &'static str,
    /// Redundant skewed block, 2σ.
    pub redundant: f64,
    /// Orthogonal block with the same sensors, 2σ.
    pub orthogonal: f64,
    /// redundant ÷ orthogonal.
    pub ratio: f64,
}

/// A claim with its ratio.
const fn claim(
    quantity: &'static str,
    unit: &'static str,
    redundant: f64,
    orthogonal: f64,
) -> PublishedClaim {
    PublishedClaim {
        quantity,
        unit,
        redundant,
        orthogonal,
        ratio: redundant / orthogonal,
    }
}

/// The published table: roll/pitch, heading (÷ cos φ), position, baro altitude.
pub const PUBLISHED_CLAIMS: [PublishedClaim; 4] = [
    claim("roll/pitch", "°", 0.22, 0.38),
    claim("heading (× cos φ)", "°", 0.3, 0.45),
    claim("position", "m", 600.0, 1400.0),
    claim("baro altitude", "m", 1.3, 2.1),
];

/// The comparison. Runs are deterministic per seed, so equal configurations give equal reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct McReport {
    /// Runs made.
    pub runs: usize,
    /// Seed of the first run (run k uses `first_seed + k`).
    pub first_seed: u64,
    /// Simulated flight time, s.
    pub duration_s: f64,
    /// The simulator scenario flown.
    pub scenario: rins_sim::Scenario,
    /// Simulated IMU rate, Hz.
    pub imu_rate_hz: f64,
    /// Kill time, s, when the fault experiment ran.
    pub kill_at_s: Option<f64>,
    /// Gyro channel biases calibrated in the fuser from the static window (see
    /// [`super::McConfig::calibrate_gyro_channels_at_rest`]).
    pub gyro_channels_calibrated_at_rest: bool,
    /// The skewed redundant block.
    pub redundant: SystemReport,
    /// The orthogonal triad built from the same sensors.
    pub orthogonal: SystemReport,
    /// Redundant ÷ orthogonal of the 2σ of the final errors (roll/pitch and position per axis).
    pub final_two_sigma_ratio: Ratios,
    /// Redundant ÷ orthogonal of the mean over runs of the RMS over the flight.
    pub rms_mean_ratio: Ratios,
    /// The published claims, for the ratio: their absolute numbers come from a 5 h flight with
    /// other aiding and are not comparable with these.
    pub published_claims: [PublishedClaim; 4],
    /// Every run, for plots and checks.
    pub records: Vec<RunRecord>,
}

/// Statistics over runs of one window.
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

/// √ of the variance factors: per-axis σ in units of the channel σ.
fn noise_amplification(factors: [f64; 3]) -> [f64; 3] {
    factors.map(f64::sqrt)
}

/// One system (`index` into the prepared systems) over its runs.
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
    /// The report of `records`, the runs from `first_seed` on.
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
            scenario: prepared.sim.scenario,
            imu_rate_hz: prepared.sim.imu_rate_hz,
            kill_at_s,
            gyro_channels_calibrated_at_rest: prepared.gyro_channel_bias_ticks.is_some(),
            redundant,
            orthogonal,
            final_two_sigma_ratio,
            rms_mean_ratio,
            published_claims: PUBLISHED_CLAIMS,
            records,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_ratios() {
        assert!((PUBLISHED_CLAIMS[2].ratio - 600.0 / 1400.0).abs() < 1e-15);
        assert!((PUBLISHED_CLAIMS[0].ratio - 0.22 / 0.38).abs() < 1e-15);
    }
}
