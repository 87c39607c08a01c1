//! Monte Carlo comparison of a redundant skewed sensor block with an orthogonal triad built from
//! the same sensors (the experiment of the structural-redundancy paper, see docs/design.md), run
//! in-process on the product's libraries: simulator → fuser → navigator with the altimeter's baro
//! aiding.
//!
//! Per run and system: the simulator flies the UAV profile at the IMU rate; the fuser solves body
//! rate and specific force by least squares over the valid channels; the navigator aligns on the
//! static start (gyro bias, roll/pitch, magnetometer heading) and then integrates, blending the
//! altimeter's height. Errors against truth are recorded from the alignment on.
//!
//! Fault experiment: at `kill_at_s` the run forks; in the copy one gyro channel goes dead. The
//! orthogonal block then has two gyro axes, the fuser reports too few channels and the navigator
//! stops; the redundant block continues on three skewed axes. Since the simulator's channel noise
//! is drawn per channel, the copy's other channels carry exactly the same noise as the original:
//! the difference after the kill is due to the lost channel alone.

pub mod config;
pub mod errors;
pub(crate) mod pipeline;
pub mod report;
pub mod run;
mod table;

pub use config::{McConfig, McError, SystemSpec};
pub use errors::{NavErrors, RmsErrors, WindowResult};
pub use report::McReport;
pub use run::{KillRun, RunRecord, SystemRun};

/// Runs the comparison on `config.threads` threads. `progress(done, total)` is called on the
/// calling thread with 0 first and after each finished run. Results do not depend on the number
/// of threads: run k always uses seed `first_seed + k`.
pub fn run_monte_carlo(
    config: &McConfig,
    mut progress: impl FnMut(usize, usize),
) -> Result<McReport, McError> {
    let prepared = config.prepare()?;
    let total = config.runs;
    let seed = |k: usize| config.first_seed.wrapping_add(k as u64);
    progress(0, total);
    let records = crate::parallel::run_indexed(
        total,
        config.threads,
        |k| run::run_pair(&prepared, seed(k)),
        progress,
    )?;
    Ok(McReport::new(&prepared, config.first_seed, records))
}
