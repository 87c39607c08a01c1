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

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc;

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
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let mut records: Vec<Option<run::RunRecord>> = vec![None; total];
    let mut first_error = None;
    progress(0, total);

    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel();
        for _ in 0..config.threads.min(total) {
            let tx = tx.clone();
            let (prepared, next, stop) = (&prepared, &next, &stop);
            scope.spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    if k >= total {
                        break;
                    }
                    if tx.send((k, run::run_pair(prepared, seed(k)))).is_err() {
                        break;
                    }
                }
            });
        }
        drop(tx);
        let mut done = 0;
        for (k, result) in rx {
            match result {
                Ok(record) => records[k] = Some(record),
                Err(e) => {
                    stop.store(true, Ordering::Relaxed);
                    first_error.get_or_insert(e);
                }
            }
            done += 1;
            progress(done, total);
        }
    });
    if let Some(e) = first_error {
        return Err(e);
    }
    // Every index below `total` was taken by exactly one worker and sent back.
    let records = records.into_iter().flatten().collect();
    Ok(McReport::new(&prepared, config.first_seed, records))
}
