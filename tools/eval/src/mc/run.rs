//! One Monte Carlo run of one system: the fault-free flight and, forked from it at the kill time,
//! the same flight with one gyro channel dead.

use serde::Serialize;

use super::config::{McError, Prepared, PreparedSystem};
use super::errors::{ERROR_SAMPLE_TICKS, Window, WindowResult};
use super::pipeline::Pipeline;

/// The fault experiment of one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct KillRun {
    /// The fault-free flight from the kill time to the end.
    pub nominal: WindowResult,
    /// The same flight, same seed, with the channel dead from the kill time on.
    pub faulted: WindowResult,
    /// Largest attitude difference between the two flights over the first
    /// [`JUMP_WINDOW_S`] after the kill, °: what the reconfiguration itself does to the solution
    /// (`None` when either flight had no solution then).
    pub reconfiguration_jump_deg: Option<f64>,
}

/// Span after the kill over which the reconfiguration jump is measured, s: long enough for a
/// step in the fused rate to show in the attitude, short enough that the two flights' different
/// noise has not yet drifted apart (the angle random walk of the difference is ~0.01° per √s).
pub const JUMP_WINDOW_S: f64 = 1.0;

/// Angle between two attitudes given as `[w, x, y, z]` unit quaternions, °.
pub(crate) fn attitude_difference_deg(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let dot = a
        .iter()
        .zip(b)
        .map(|(x, y)| x * y)
        .sum::<f64>()
        .abs()
        .min(1.0);
    (2.0 * dot.acos()).to_degrees()
}

/// One system in one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SystemRun {
    /// Device time of the first navigation solution, s; `None` if alignment never completed.
    pub aligned_at_s: Option<f64>,
    /// Fault-free flight from the alignment to the end (`None` without alignment).
    pub nominal: Option<WindowResult>,
    /// Fault experiment (`None` when not configured, past the end, or before the alignment).
    pub kill: Option<KillRun>,
}

/// Both systems in one run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RunRecord {
    /// Seed of the simulator (trajectory, environment and sensor errors) for both systems.
    pub seed: u64,
    /// The redundant system.
    pub redundant: SystemRun,
    /// The orthogonal system.
    pub orthogonal: SystemRun,
}

/// Flies one system; `prepared.ticks` IMU ticks. Allocation-free per tick (the fork at the kill
/// time clones the pipeline once).
pub(crate) fn run_system(
    prepared: &Prepared,
    system: &PreparedSystem,
    seed: u64,
) -> Result<SystemRun, McError> {
    let tick_s = 1.0 / prepared.sim.imu_rate_hz;
    let last_tick = prepared.ticks.saturating_sub(1);
    let kill_tick = prepared.kill_tick;
    let mut pipeline = Pipeline::new(prepared, system, seed)?;
    let mut nominal: Option<Window> = None;
    let mut aligned_at_s = None;
    let mut fork: Option<(Pipeline, Window, Window)> = None;
    let jump_ticks = (JUMP_WINDOW_S / tick_s).round() as u64;
    let mut jump: Option<f64> = None;

    for k in 0..prepared.ticks {
        if Some(k) == kill_tick && aligned_at_s.is_some() {
            let mut faulted = pipeline.clone();
            faulted.kill_gyro(prepared.kill_channel)?;
            let start_s = k as f64 * tick_s;
            fork = Some((
                faulted,
                Window::new(start_s, tick_s),
                Window::new(start_s, tick_s),
            ));
        }
        pipeline.step();
        if aligned_at_s.is_none() && pipeline.aligned() {
            aligned_at_s = Some(k as f64 * tick_s);
            nominal = Some(Window::new(k as f64 * tick_s, tick_s));
        }
        let sample = k % ERROR_SAMPLE_TICKS == 0;
        let is_last = k == last_tick;
        if let Some(w) = nominal.as_mut() {
            w.push(
                pipeline.solution(),
                pipeline.degraded(),
                pipeline.truth(),
                sample,
                is_last,
            );
        }
        if let Some((faulted, nominal_after, faulted_window)) = fork.as_mut() {
            faulted.step();
            if let (Some(kill), Some(a), Some(b)) =
                (kill_tick, pipeline.solution(), faulted.solution())
                && k < kill + jump_ticks
            {
                let d = attitude_difference_deg(&a.quaternion, &b.quaternion);
                jump = Some(jump.map_or(d, |j: f64| j.max(d)));
            }
            nominal_after.push(
                pipeline.solution(),
                pipeline.degraded(),
                pipeline.truth(),
                sample,
                is_last,
            );
            faulted_window.push(
                faulted.solution(),
                faulted.degraded(),
                faulted.truth(),
                sample,
                is_last,
            );
        }
    }
    Ok(SystemRun {
        aligned_at_s,
        nominal: nominal.map(|w| w.result()),
        kill: fork.map(|(_, n, f)| KillRun {
            nominal: n.result(),
            faulted: f.result(),
            reconfiguration_jump_deg: jump,
        }),
    })
}

/// Both systems with the same seed.
pub(crate) fn run_pair(prepared: &Prepared, seed: u64) -> Result<RunRecord, McError> {
    let [redundant, orthogonal] = &prepared.systems;
    Ok(RunRecord {
        seed,
        redundant: run_system(prepared, redundant, seed)?,
        orthogonal: run_system(prepared, orthogonal, seed)?,
    })
}

#[cfg(test)]
mod tests {
    use super::attitude_difference_deg;

    #[test]
    fn attitude_difference_of_a_small_rotation() {
        let h = 0.1f64.to_radians() / 2.0;
        let a = [1.0, 0.0, 0.0, 0.0];
        let b = [h.cos(), 0.0, 0.0, h.sin()];
        assert!((attitude_difference_deg(&a, &b) - 0.1).abs() < 1e-9);
        // q and −q are the same attitude.
        let minus_b = b.map(|c| -c);
        assert!((attitude_difference_deg(&a, &minus_b) - 0.1).abs() < 1e-9);
    }
}
