//! `rins eval quadrotor --mode ahrs --live`: each flight's cross-validated fused run repeated
//! through the running processes. The flight is imported as a recording of one redundant block
//! (twelve channels in the units' own axes, 16-bit counts: [`rins_eval::import::quadrotor`]), a
//! private deployment runs fusion, the altimeter and the navigator lanes with the recording's
//! block and the run's navigator settings and in-flight start (`[navigator.start]`, with the
//! mounting and gyro-bias prior the cross-validation chose), and lane 0's attitude is scored
//! exactly as the in-process one. The difference to the in-process run is split into the
//! converter's share (the same run in process on what fusion makes of the counts) and the
//! processes' own.

use std::collections::HashMap;
use std::path::Path;

use anyhow::{Context, Result, bail};
use ipc_types::NavState;
use rins::config::RinsConfig;
use rins::replay::input::RawSample;
use rins_eval::datasets::quadrotor::load_each;
use rins_eval::import::ImportedRun;
use rins_eval::import::quadrotor::{Profile, import_trial};
use rins_eval::quadrotor_ahrs::AhrsReport;
use rins_eval::quadrotor_ahrs::live::{LiveFlight, ScoredRun, summarise};
use rins_eval::quadrotor_ahrs::run::AttitudeTrace;
use rins_eval::quadrotor_nav::frames::{BodySample, Motion};
use rins_runtime::shutdown::Shutdown;

use super::{Scratch, deploy, device_index, each_live, fused, in_process, navigating, reparsed};

/// A flight as the running processes get it.
struct Recording {
    /// The raw frames, in order.
    raw: Vec<RawSample>,
    /// Sample index of each frame's device time.
    index: HashMap<u64, usize>,
    /// The recording's configuration (block, fusion; the profile's navigator).
    cfg: RinsConfig,
}

/// Every flight of `runs` imported from `dir`, by name, under the UAV profile placed at the
/// runs' origin.
fn import(dir: &Path, runs: &[ScoredRun]) -> Result<HashMap<String, ImportedRun>> {
    let mut imported = HashMap::new();
    let loaded = load_each(dir, |_, _| ())
        .with_context(|| format!("cannot list the flights in {}", dir.display()))?;
    for (entry, trial) in loaded {
        let Some(run) = runs.iter().find(|r| r.flight == entry.name) else {
            continue;
        };
        let trial = trial.with_context(|| format!("{}: cannot load", entry.name))?;
        let profile = Profile {
            text: rins::config::UAV,
            name: "uav",
            origin: run.config.origin,
        };
        imported.insert(entry.name.clone(), import_trial(&trial, &profile)?);
    }
    Ok(imported)
}

fn recording(run: &ScoredRun, imported: &ImportedRun) -> Result<Recording> {
    let cfg = RinsConfig::parse(
        &imported.config_fragment,
        &format!("{}: imported configuration", run.flight),
    )?;
    if imported.imu.len() != run.motion.samples.len() {
        bail!(
            "{}: {} imported frames for {} samples of the fused motion",
            run.flight,
            imported.imu.len(),
            run.motion.samples.len()
        );
    }
    let raw: Vec<RawSample> = imported.imu.iter().copied().map(RawSample::Imu).collect();
    Ok(Recording {
        index: device_index(&raw),
        raw,
        cfg,
    })
}

/// What fusion makes of the frames, as the motion the in-process navigator is fed.
fn fused_in_process(cfg: &RinsConfig, rec: &Recording, motion: &Motion) -> Result<Motion> {
    let samples = fused(cfg, &rec.raw)?
        .into_iter()
        .map(|(gyro_rps, accel_mps2)| BodySample {
            gyro_rps,
            accel_mps2,
        })
        .collect();
    Ok(Motion {
        samples,
        ..motion.clone()
    })
}

/// The deployment's configuration for `run`: the recording's (block, fusion), with the run's
/// navigator settings and its in-flight start. Refused when the navigator it describes is not
/// the run's.
fn live_config(recorded: &RinsConfig, run: &ScoredRun) -> Result<RinsConfig> {
    let (start, aided) = run.in_flight_start();
    let mut cfg = recorded.clone();
    // The flights start in the air: no rest to learn the gyro biases on.
    cfg.fusion.rest_bias_s = 0.0;
    let nav = &mut cfg.navigator;
    nav.initial_latitude_deg = Some(aided.origin[0].to_degrees());
    nav.initial_longitude_deg = Some(aided.origin[1].to_degrees());
    nav.initial_altitude_m = aided.origin[2];
    nav.tilt = aided.tilt;
    nav.baro = aided.baro;
    nav.mag = aided.mag;
    nav.zupt = aided.zupt;
    nav.ekf = aided.noise;
    nav.start = Some(start);
    let parsed = reparsed(&cfg, "the live configuration")?;
    // The alignment's settings (its gravity follows the stated latitude) are not used: the
    // navigator starts in flight.
    let mut expected = aided;
    expected.align = parsed.navigator.aided_config().align;
    if parsed.navigator.aided_config() != expected {
        bail!(
            "{}: the navigator of the live configuration is not the evaluated one:\n{:?}\nagainst\n{:?}",
            run.flight,
            parsed.navigator.aided_config(),
            expected
        );
    }
    Ok(parsed)
}

/// Lane `states`' attitude as a trace on the flight's time base (see [`ScoredRun::trace_from`]).
fn trace_of(run: &ScoredRun, rec: &Recording, states: &[NavState]) -> AttitudeTrace {
    run.trace_from(navigating(states, &rec.index).map(|(j, n)| (j, n.quaternion)))
}

/// One flight through a private deployment.
fn fly(
    imported: &ImportedRun,
    run: &ScoredRun,
    scratch: &Scratch,
    shutdown: &Shutdown,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LiveFlight> {
    let rec = recording(run, imported)?;
    let cfg = live_config(&rec.cfg, run)?;
    let out = deploy(&cfg, &run.flight, &rec.raw, scratch, shutdown, progress)
        .with_context(|| format!("{}: live run", run.flight))?;
    let live = trace_of(run, &rec, &out.nav[0]);
    let same_input = run.rerun(&fused_in_process(&cfg, &rec, &run.motion)?);
    // The deployment's library code in this process, fed the same frames.
    let pipeline = in_process(&cfg, &rec.raw)?;
    let in_process = trace_of(run, &rec, &pipeline[0]);
    let (live_vs_offline, missing) = run.max_difference_deg(&live, &run.trace);
    Ok(LiveFlight {
        live_roll_pitch_rmse_deg: run.score_deg(&live),
        live_vs_offline_max_diff_deg: live_vs_offline,
        live_vs_same_input_max_diff_deg: run.max_difference_deg(&live, &in_process).0,
        quantisation_max_diff_deg: run.max_difference_deg(&same_input, &run.trace).0,
        quantisation_max_tilt_diff_deg: run.max_tilt_difference_deg(&same_input, &run.trace),
        live_rows_missing: missing,
        live_fdi_events: out.channel_events,
        live_excluded_channels: out.excluded_channels,
    })
}

/// Runs every flight of `runs` (in the report's flight order) live and adds the figures to
/// `report`.
pub fn quadrotor_ahrs(dir: &Path, runs: &[ScoredRun], report: &mut AhrsReport) -> Result<()> {
    let shutdown = Shutdown::install()?;
    let imported = import(dir, runs)?;
    let flights = each_live("eval quadrotor live", runs, |run, scratch, progress| {
        let Some(flight) = imported.get(&run.flight) else {
            bail!("{}: not imported", run.flight);
        };
        fly(flight, run, scratch, &shutdown, progress)
    })?;
    for (run, live) in runs.iter().zip(&flights) {
        if let Some(result) = report.flights.iter_mut().find(|f| f.name == run.flight) {
            result.live = Some(live.clone());
        }
    }
    report.live = Some(summarise(
        "each flight imported as one block: 12 channels in the units' own axes, 16-bit counts",
        &flights,
    ));
    Ok(())
}
