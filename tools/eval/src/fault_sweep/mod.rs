//! Fault sweep: one fault per run, injected into the configured chain in flight, followed
//! through fusion's detection and isolation and the navigator's integrity.
//!
//! The chain is the one `rins up` runs, in-process on the `uav` scenario: simulator → fuser (the
//! configured `[fusion]` table) → navigator, barometer → altimeter → navigator, magnetometer →
//! navigator, with fusion's fault report passed to the navigator. For each injection time the
//! clean chain is flown to that time once and forked; each fork gets one fault on one channel
//! (bias steps, a ramp, a noise increase, sized in the channel's σ) and flies the window. Since
//! the simulator draws each channel's noise from its own stream, every fork carries exactly the
//! noise of the others: the differences between rows are the faults'.
//!
//! Per run: when fusion first flagged the fault (the channel not Ok, or a detected-not-isolated
//! fault on its sensor type) and when it excluded the channel; the largest attitude error against
//! the truth after the injection, the largest attitude and horizontal errors of the samples whose
//! integrity said ok, and the share of samples it said ok. A clean run with the same seed counts
//! the false alarms.

pub mod config;
pub mod report;
mod run;

pub use config::{SweepChannel, SweepConfig, SweepFault, TARGET_ATT_ERR_DEG};
pub use report::{SweepReport, SweepSummary};
pub use run::{CleanRun, FaultRun};

use crate::mc::McError;

/// One job of the pool: a faulted run (or the reference) at an injection time, or the clean run.
#[derive(Debug, Clone, Copy)]
enum Job {
    Fault {
        at: usize,
        fault: Option<(SweepChannel, SweepFault)>,
    },
    Clean,
}

enum Outcome {
    Fault(FaultRun),
    Clean(CleanRun),
}

/// Runs the sweep on `config.threads` threads. `progress(done, total)` is called on the calling
/// thread with 0 first and after each finished run. The result does not depend on the number of
/// threads.
pub fn run_fault_sweep(
    config: &SweepConfig,
    mut progress: impl FnMut(usize, usize),
) -> Result<SweepReport, McError> {
    let prepared = config.prepare()?;
    let mut jobs = vec![Job::Clean];
    for at in 0..prepared.inject_ticks.len() {
        jobs.push(Job::Fault { at, fault: None });
        for &channel in &prepared.channels {
            for &fault in &prepared.faults {
                jobs.push(Job::Fault {
                    at,
                    fault: Some((channel, fault)),
                });
            }
        }
    }
    let total = jobs.len();
    progress(0, total);
    // The forks' common start, one per injection time. The injection must find the navigator
    // navigating: a fault during the alignment is another experiment.
    let mut bases = Vec::with_capacity(prepared.inject_ticks.len());
    for &tick in &prepared.inject_ticks {
        let base = run::base_at(&prepared, tick)?;
        if !base.aligned() {
            return Err(rins_fusion::ConfigError::new(
                "inject_at_s",
                tick as f64 * prepared.tick_s,
                "the navigator is still aligning then: inject later",
            )
            .within("sweep")
            .into());
        }
        bases.push(base);
    }
    let clean_ticks = prepared
        .inject_ticks
        .iter()
        .map(|t| t + prepared.window_ticks)
        .max()
        .unwrap_or(prepared.window_ticks);

    let outcomes = crate::parallel::run_indexed(
        total,
        config.threads,
        |k| match jobs[k] {
            Job::Clean => run::run_clean(&prepared, clean_ticks).map(Outcome::Clean),
            Job::Fault { at, fault } => {
                run::run_fault(&prepared, &bases[at], prepared.inject_ticks[at], fault)
                    .map(Outcome::Fault)
            }
        },
        progress,
    )?;
    let mut clean = None;
    let mut runs = Vec::with_capacity(total);
    for outcome in outcomes {
        match outcome {
            Outcome::Clean(c) => clean = Some(c),
            Outcome::Fault(r) => runs.push(r),
        }
    }
    // Every job was taken by exactly one worker and sent back, the clean one included.
    let clean = clean.unwrap_or(CleanRun {
        duration_s: 0.0,
        false_alarms: 0,
        flagged_s: 0.0,
        first_false_alarm_s: None,
        att_err_deg_max: None,
        att_err_deg_max_while_ok: None,
        tilt_err_deg_max_while_ok: None,
        ok_share: 0.0,
    });
    Ok(SweepReport::new(&prepared, config, runs, clean))
}
