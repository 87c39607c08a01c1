//! `rins mc`: the Monte Carlo comparison of the redundant skewed block with an orthogonal triad
//! (rins-eval), with a progress bar on stderr and the report table (or JSON) on stdout.

use anyhow::{Result, anyhow};
use rins_eval::mc::config::DEFAULT_KILL_AT_S;
use rins_eval::mc::{McConfig, run_monte_carlo};

use super::progress::Progress;
use crate::cli::McArgs;
use crate::config;

/// The comparison's settings from the defaults, the configuration file (sim, navigator and
/// altimeter) and the command line.
fn mc_config(args: &McArgs) -> Result<McConfig> {
    let mut mc = McConfig::default();
    if let Some(path) = args.config.as_deref() {
        let cfg = config::load(Some(path))?;
        // The experiment flies the UAV profile whatever scenario the file runs the service with.
        mc.sim = rins_sim::SimConfig {
            scenario: rins_sim::Scenario::Uav,
            ..cfg.sim
        };
        mc.navigator = cfg.navigator;
        mc.altimeter = cfg.altimeter;
    }
    if let Some(scenario) = args.scenario {
        mc.sim.scenario = scenario.into();
    }
    if let Some(runs) = args.runs {
        mc.runs = runs;
    }
    if let Some(threads) = args.threads {
        mc.threads = threads;
    }
    if let Some(d) = args.duration {
        if !(d.is_finite() && d > 0.0) {
            return Err(anyhow!(
                "--duration {d}: must be a positive number of seconds"
            ));
        }
        mc.duration_s = Some(d);
    }
    mc.kill_at_s = Some(match (args.kill_at, args.duration) {
        (Some(k), _) => k,
        // A short flight would end before the default kill: put the kill in its middle.
        (None, Some(d)) if d <= DEFAULT_KILL_AT_S => d / 2.0,
        (None, _) => DEFAULT_KILL_AT_S,
    });
    Ok(mc)
}

pub fn run(args: &McArgs) -> Result<()> {
    let mc = mc_config(args)?;
    let mut bar = Progress::new("mc runs");
    let report =
        run_monte_carlo(&mc, |done, total| bar.set(done, total)).map_err(|e| anyhow!("mc: {e}"))?;
    bar.finish();
    super::report_out::print_report(args.json, &report, |r| r.to_table())
}
