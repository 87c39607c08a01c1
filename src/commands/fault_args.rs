//! Timed faults from the command line (`--inject SPEC`, `--faults FILE`), checked against the
//! configured sensor block.

use anyhow::{Result, anyhow};
use rins_sim::FaultParseError;
use rins_sim::fault_schedule::{FaultFile, ScheduledFault};
use rins_sim::sim_command::FittedSources;

use crate::cli::FaultArgs;
use crate::config::RinsConfig;

/// What the configured deployment fits: the sensor block's gyro and accelerometer channels, and
/// whether a (simulated) GNSS receiver runs.
pub fn fitted_sources(cfg: &RinsConfig) -> Result<FittedSources> {
    let (gyro, accel) = cfg.geometries()?;
    Ok(FittedSources {
        n_gyro: gyro.n(),
        n_accel: accel.n(),
        gnss_receiver: cfg.gnss.enabled || cfg.sim.gnss.enabled,
    })
}

/// Every scheduled fault of `args`, each checked against what `sources` fits; errors name the
/// option or file and the offending token.
pub fn schedule(args: &FaultArgs, sources: &FittedSources) -> Result<Vec<ScheduledFault>> {
    let fitted = |f: &ScheduledFault| f.command.check_fitted(sources);
    let mut faults = Vec::new();
    for spec in &args.inject {
        let fault = ScheduledFault::parse(spec)
            .and_then(|f| {
                fitted(&f)
                    .map_err(|e| e.within(&format!("{spec:?}")))
                    .map(|()| f)
            })
            .map_err(|e: FaultParseError| anyhow!("--inject {e}"))?;
        faults.push(fault);
    }
    if let Some(path) = &args.faults {
        let text = rins_runtime::bounded_file::read_text(
            path,
            "fault file",
            rins_runtime::bounded_file::DEFAULT_LIMIT,
        )?;
        let file: FaultFile = toml::from_str(&text)
            .map_err(|e| anyhow!("{}: {}", path.display(), e.to_string().trim_end()))?;
        let scheduled = file
            .schedule()
            .map_err(|e| anyhow!("{}: {e}", path.display()))?;
        for (i, f) in scheduled.iter().enumerate() {
            fitted(f)
                .map_err(|e| anyhow!("{}: {}", path.display(), e.within(&format!("fault[{i}]"))))?;
        }
        faults.extend(scheduled);
    }
    Ok(faults)
}
