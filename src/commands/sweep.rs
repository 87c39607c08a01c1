//! `rins sweep`: the fault sweep (rins-eval) on the configured chain, with a progress bar on
//! stderr and the table (or JSON) on stdout.

use anyhow::{Result, anyhow};
use rins_eval::fault_sweep::config::{MAX_THREADS, MAX_WINDOW_S};
use rins_eval::fault_sweep::{SweepChannel, SweepConfig, run_fault_sweep};

use super::progress::Progress;
use crate::cli::SweepArgs;
use crate::config;

/// The sweep's settings: the configuration's chain (built in unless `--config`), then the
/// command line. Each option is checked here so that its error names the option.
fn sweep_config(args: &SweepArgs) -> Result<SweepConfig> {
    let cfg = config::load(args.config.as_deref())?;
    let mut sweep = SweepConfig::new(cfg.sim, cfg.fusion, cfg.altimeter, cfg.navigator);
    if let Some(seed) = args.seed {
        sweep.seed = seed;
    }
    if !args.at.is_empty() {
        for &t in &args.at {
            if !(t.is_finite() && t > 0.0 && t <= 86_400.0) {
                return Err(anyhow!("--at {t}: must be a time in (0, 86400] s"));
            }
        }
        sweep.inject_at_s = args.at.clone();
    }
    if let Some(w) = args.window {
        if !(w.is_finite() && w > 0.0 && w <= MAX_WINDOW_S) {
            return Err(anyhow!(
                "--window {w}: must be a positive number of seconds up to {MAX_WINDOW_S}"
            ));
        }
        sweep.window_s = w;
    }
    for name in &args.channel {
        let channel = SweepChannel::parse(name).ok_or_else(|| {
            anyhow!("--channel {name:?}: not a channel (gyro or accel and its index, e.g. gyro2)")
        })?;
        sweep.channels.push(channel);
    }
    if let Some(threads) = args.threads {
        if !(1..=MAX_THREADS).contains(&threads) {
            return Err(anyhow!("--threads {threads}: must be in 1..={MAX_THREADS}"));
        }
        sweep.threads = threads;
    }
    Ok(sweep)
}

pub fn run(args: &SweepArgs) -> Result<()> {
    let sweep = sweep_config(args)?;
    let mut bar = Progress::new("sweep runs");
    let report = run_fault_sweep(&sweep, |done, total| bar.set(done, total))
        .map_err(|e| anyhow!("sweep: {e}"))?;
    bar.finish();
    super::report_out::print_report(args.json, &report, |r| r.to_table())
}
