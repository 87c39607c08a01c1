//! What a soak is asked to run (the command line's `rins soak` options), and their checks.

use anyhow::{Result, anyhow, bail};

use crate::fault_plan::FaultKind;

/// What a soak runs (the command line's `rins soak` options).
#[derive(Debug, Clone, PartialEq)]
pub struct SoakArgs {
    /// How long to run, minutes.
    pub minutes: f64,
    /// Seed of the fault schedule.
    pub seed: u64,
    /// Shortest time between two faults, s (at least 0.5).
    pub min_interval_s: f64,
    /// Longest time between two faults, s (at least `min_interval_s`); each interval is drawn
    /// between the two.
    pub max_interval_s: f64,
    /// Kinds of fault, comma-separated: kill, hang, sensor, disconnect.
    pub faults: String,
    /// Print the summary as one JSON object (stdout holds nothing else) instead of text.
    pub json: bool,
    /// The deployment profile `rins up` runs with (its `--profile`): `shared`, `dedicated` or
    /// `auto`; `rins up` checks it.
    pub profile: String,
}

/// Checks the arguments (each error names the option and its value); returns the fault kinds asked for.
pub(crate) fn check_args(args: &SoakArgs) -> Result<Vec<FaultKind>> {
    if !(args.minutes.is_finite() && args.minutes > 0.0 && args.minutes <= 24.0 * 60.0) {
        bail!("--minutes {}: must be in (0, 1440]", args.minutes);
    }
    if !(args.min_interval_s.is_finite()
        && args.min_interval_s >= 0.5
        && args.max_interval_s.is_finite()
        && args.max_interval_s >= args.min_interval_s)
    {
        bail!(
            "--min-interval {} / --max-interval {}: need 0.5 <= min <= max seconds",
            args.min_interval_s,
            args.max_interval_s
        );
    }
    FaultKind::parse_list(&args.faults).map_err(|e| anyhow!(e))
}
