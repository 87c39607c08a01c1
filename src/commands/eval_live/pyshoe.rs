//! `rins eval pyshoe --live`: each walk's held-out rins run repeated through the running
//! processes. The walk is imported as a recording of one triad in 16-bit counts
//! ([`rins_eval::import::pyshoe`]), a private deployment runs fusion, the altimeter and the
//! navigator lanes with the recording's block and the pedestrian profile's navigator carrying the
//! stance detector setting the evaluation chose for that walk, and lane 0's positions are scored
//! exactly as the in-process ones. The difference to the in-process run is split into the
//! input's share (the same run in process on what fusion makes of the counts) and the
//! processes' own.

use anyhow::{Context, Result, bail};
use rins::config::RinsConfig;
use rins::replay::input::RawSample;
use rins_eval::foot::PyshoeReport;
use rins_eval::foot::live::{LiveWalk, PositionTrace, ScoredWalk, summarise};
use rins_eval::import::pyshoe::import_trial;
use rins_eval::import::quadrotor::Profile;
use rins_runtime::shutdown::Shutdown;

use super::{Scratch, deploy, device_index, each_live, fused, in_process, navigating, reparsed};

/// The deployment's configuration for `walk`: the imported recording's (device, block,
/// fusion), with the profile's navigator carrying the walk's stance and gyro lag settings. Refused when the
/// navigator it describes is not the one the walk was scored with.
fn live_config(
    recorded: &RinsConfig,
    profile: &RinsConfig,
    walk: &ScoredWalk,
) -> Result<RinsConfig> {
    let mut cfg = recorded.clone();
    cfg.navigator = profile.navigator.clone();
    let expected = walk.navigator_config();
    cfg.navigator.stance = expected.stance;
    cfg.navigator.gyro_lag_s = expected.gyro_lag_s;
    cfg.navigator.baro = expected.baro;
    cfg.navigator.mag = expected.mag;
    let parsed = reparsed(&cfg, "the live configuration")?;
    if parsed.navigator.aided_config() != expected {
        bail!(
            "{}: the navigator of the live configuration is not the evaluated one:\n{:?}\nagainst\n{:?}",
            walk.trial.name,
            parsed.navigator.aided_config(),
            expected
        );
    }
    Ok(parsed)
}

/// Lane `states`' positions as a trace on the walk's sample base.
fn trace_of(
    walk: &ScoredWalk,
    index: &std::collections::HashMap<u64, usize>,
    states: &[ipc_types::NavState],
) -> PositionTrace {
    walk.trace_from(
        navigating(states, index)
            .map(|(j, n)| (j, [n.latitude_rad, n.longitude_rad, n.altitude_m])),
    )
}

/// One walk through a private deployment.
fn walk_live(
    profile: &RinsConfig,
    profile_text: &str,
    walk: &ScoredWalk,
    scratch: &Scratch,
    shutdown: &Shutdown,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LiveWalk> {
    let name = &walk.trial.name;
    let imported = import_trial(
        &walk.trial,
        &Profile {
            text: profile_text,
            name: "pedestrian",
            origin: walk.config.origin,
        },
    )?;
    if imported.imu.len() != walk.trial.samples.len() {
        bail!(
            "{name}: {} imported frames for {} samples",
            imported.imu.len(),
            walk.trial.samples.len()
        );
    }
    let recorded = RinsConfig::parse(
        &imported.config_fragment,
        &format!("{name}: imported configuration"),
    )?;
    let cfg = live_config(&recorded, profile, walk)?;
    let raw: Vec<RawSample> = imported.imu.iter().copied().map(RawSample::Imu).collect();
    let index = device_index(&raw);
    let out = deploy(&cfg, name, &raw, scratch, shutdown, progress)
        .with_context(|| format!("{name}: live run"))?;
    let live = trace_of(walk, &index, &out.nav[0]);
    let same_input = trace_of(walk, &index, &in_process(&cfg, &raw)?[0]);
    let quantised = walk.rerun(fused(&cfg, &raw)?);
    let offline = walk.trace();
    let score = walk.score(&live);
    let scored = walk.score(&offline);
    let offset = match (live.aligned_at, offline.aligned_at) {
        (Some(a), Some(b)) => a as i64 - b as i64,
        _ => 0,
    };
    Ok(LiveWalk {
        offline_rmse_m: scored.rmse_2d_m,
        offline_armse_m: scored.armse_m,
        live_rmse_m: score.rmse_2d_m,
        live_armse_m: score.armse_m,
        live_vs_offline_max_diff_m: walk.max_difference_m(&live, &offline),
        live_vs_same_input_max_diff_m: walk.max_difference_m(&live, &same_input),
        quantisation_max_diff_m: walk.max_difference_m(&quantised, &offline),
        live_alignment_offset_samples: offset,
        live_samples_missing: live.missing,
        live_fdi_events: out.channel_events,
        live_excluded_channels: out.excluded_channels,
    })
}

/// Runs every walk of `walks` live under the pedestrian `profile` (its text `profile_text`) and
/// adds the figures to `report`.
pub fn pyshoe(
    profile: &RinsConfig,
    profile_text: &str,
    walks: &[ScoredWalk],
    report: &mut PyshoeReport,
) -> Result<()> {
    let shutdown = Shutdown::install()?;
    let results = each_live("eval pyshoe live", walks, |walk, scratch, progress| {
        walk_live(profile, profile_text, walk, scratch, &shutdown, progress)
    })?;
    for (walk, live) in walks.iter().zip(&results) {
        if let Some(t) = report
            .trials
            .iter_mut()
            .find(|t| t.trial == walk.trial.name)
        {
            t.live = Some(live.clone());
        }
    }
    report.live = Some(summarise(
        "each walk imported as one triad in 16-bit counts",
        &results,
    ));
    Ok(())
}
