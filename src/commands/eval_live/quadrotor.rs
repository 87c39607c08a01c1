//! `rins eval quadrotor --mode ahrs|gnss --live`: each flight's scored fused run repeated
//! through the running processes (in gnss mode with the receiver's messages on the receiver's
//! topic, as the `gnss` service publishes them). The flight is imported as a recording of one redundant block
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
use rins::config::RinsConfig;
use rins::replay::input::RawSample;
use rins_eval::datasets::quadrotor::load_each;
use rins_eval::import::ImportedRun;
use rins_eval::import::quadrotor::{Profile, import_trial};
use rins_eval::quadrotor_ahrs::AhrsReport;
use rins_eval::quadrotor_ahrs::live::{
    LiveFlight, RepeatableRun, ScoredRun, live_flight, summarise,
};
use rins_eval::quadrotor_gnss::GnssReport;
use rins_eval::quadrotor_gnss::live::ScoredGnssRun;
use rins_eval::quadrotor_nav::frames::{BodySample, Motion};
use rins_navigator::inertial_core::AidedConfig;
use rins_navigator::start::InFlightStart;
use rins_runtime::shutdown::Shutdown;

use super::{Scratch, deploy, device_index, each_live, fused, in_process, navigating, reparsed};

/// A flight as the running processes get it.
struct Recording {
    /// The raw frames, in order.
    raw: Vec<RawSample>,
    /// Sample index of each IMU frame's device time.
    index: HashMap<u64, usize>,
    /// The recording's configuration (block, fusion; the profile's navigator).
    cfg: RinsConfig,
}

/// Every flight of `flights` (name, origin) imported from `dir`, by name, under the UAV profile
/// placed at the flight's origin.
fn import(dir: &Path, flights: &[(&str, [f64; 3])]) -> Result<HashMap<String, ImportedRun>> {
    let mut imported = HashMap::new();
    let loaded = load_each(dir, |_, _| ())
        .with_context(|| format!("cannot list the flights in {}", dir.display()))?;
    for (entry, trial) in loaded {
        let Some(&(_, origin)) = flights.iter().find(|(name, _)| *name == entry.name) else {
            continue;
        };
        let trial = trial.with_context(|| format!("{}: cannot load", entry.name))?;
        let profile = Profile {
            text: rins::config::UAV,
            name: "uav",
            origin,
        };
        imported.insert(entry.name.clone(), import_trial(&trial, &profile)?);
    }
    Ok(imported)
}

/// `flight`'s imported frames (one per sample of its fused `motion`) with the `extra` samples
/// (receiver messages) in the order they reached the computer.
fn recording(
    flight: &str,
    motion: &Motion,
    imported: &ImportedRun,
    extra: Vec<RawSample>,
) -> Result<Recording> {
    let cfg = RinsConfig::parse(
        &imported.config_fragment,
        &format!("{flight}: imported configuration"),
    )?;
    if imported.imu.len() != motion.samples.len() {
        bail!(
            "{flight}: {} imported frames for {} samples of the fused motion",
            imported.imu.len(),
            motion.samples.len()
        );
    }
    let mut raw: Vec<RawSample> = imported.imu.iter().copied().map(RawSample::Imu).collect();
    raw.extend(extra);
    // Stable: a message received with a frame comes after it.
    raw.sort_by_key(|s| s.rx_ns());
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

/// The deployment's configuration for `flight`: the recording's (block, fusion), with the run's
/// navigator settings `aided` and its in-flight `start`. Refused when the navigator it describes
/// is not the run's.
fn live_config(
    recorded: &RinsConfig,
    flight: &str,
    start: InFlightStart,
    aided: AidedConfig,
) -> Result<RinsConfig> {
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
    nav.gnss = aided.gnss;
    nav.ekf = aided.noise;
    nav.start = Some(start);
    let parsed = reparsed(&cfg, "the live configuration")?;
    // The alignment's settings (its gravity follows the stated latitude) are not used: the
    // navigator starts in flight.
    let mut expected = aided;
    expected.align = parsed.navigator.aided_config().align;
    if parsed.navigator.aided_config() != expected {
        bail!(
            "{flight}: the navigator of the live configuration is not the evaluated one:\n{:?}\nagainst\n{:?}",
            parsed.navigator.aided_config(),
            expected
        );
    }
    Ok(parsed)
}

/// One flight through a private deployment: its frames (with its receiver messages, if any)
/// through the processes, through the same library code in process, and the in-process run again
/// on what fusion makes of the frames.
fn fly<R: RepeatableRun>(
    imported: &ImportedRun,
    run: &R,
    scratch: &Scratch,
    shutdown: &Shutdown,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LiveFlight> {
    let messages = run
        .receiver_messages()
        .into_iter()
        .map(RawSample::Gnss)
        .collect();
    let rec = recording(run.flight(), run.motion(), imported, messages)?;
    let (start, aided) = run.in_flight_start();
    let cfg = live_config(&rec.cfg, run.flight(), start, aided)?;
    let out = deploy(&cfg, run.flight(), &rec.raw, scratch, shutdown, progress)
        .with_context(|| format!("{}: live run", run.flight()))?;
    let live = run.trace_from(navigating(&out.nav[0], &rec.index));
    let same_input = run.rerun(&fused_in_process(&cfg, &rec, run.motion())?);
    let pipeline = in_process(&cfg, &rec.raw)?;
    let same_frames = run.trace_from(navigating(&pipeline[0], &rec.index));
    Ok(live_flight(
        run,
        &live,
        &same_frames,
        &same_input,
        out.channel_events,
        out.excluded_channels,
    ))
}

/// Every run of `runs` through its own deployment, in order.
fn fly_all<R: RepeatableRun>(
    dir: &Path,
    runs: &[R],
    origin: impl Fn(&R) -> [f64; 3],
) -> Result<Vec<LiveFlight>> {
    let shutdown = Shutdown::install()?;
    let flights: Vec<(&str, [f64; 3])> = runs.iter().map(|r| (r.flight(), origin(r))).collect();
    let imported = import(dir, &flights)?;
    each_live("eval quadrotor live", runs, |run, scratch, progress| {
        let Some(flight) = imported.get(run.flight()) else {
            bail!("{}: not imported", run.flight());
        };
        fly(flight, run, scratch, &shutdown, progress)
    })
}

/// Runs every flight of `runs` (in the report's flight order) live and adds the figures to
/// `report`.
pub fn quadrotor_ahrs(dir: &Path, runs: &[ScoredRun], report: &mut AhrsReport) -> Result<()> {
    let flights = fly_all(dir, runs, |r| r.config.origin)?;
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

/// The same for the GNSS-aided runs: the receiver's messages the in-process run was fed are
/// published on the receiver's topic as the `gnss` service publishes them, received at their
/// device time.
pub fn quadrotor_gnss(dir: &Path, runs: &[ScoredGnssRun], report: &mut GnssReport) -> Result<()> {
    let flights = fly_all(dir, runs, |r| r.config.origin)?;
    for (run, live) in runs.iter().zip(&flights) {
        if let Some(result) = report.trials.iter_mut().find(|f| f.name == run.flight) {
            result.live = Some(live.clone());
        }
    }
    report.live = Some(summarise(
        "each flight imported as one block: 12 channels in the units' own axes, 16-bit counts; \
         the receiver's messages on the receiver's topic",
        &flights,
    ));
    Ok(())
}
