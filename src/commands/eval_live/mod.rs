//! The live evaluations: a recording's scored in-process run repeated through the running
//! processes (a private deployment per recording: fusion, the altimeter and the navigator lanes)
//! and scored the same way. What every recording kind shares: the deployment, the same pipeline's
//! library code run in this process on the same frames, fusion's view of the frames, and the
//! scratch directory the configurations and logs go to.

mod gnss_captures;
mod pyshoe;
mod quadrotor;

use std::collections::HashMap;
use std::path::PathBuf;

use anyhow::{Context, Result};
use ipc_types::{NavMode, NavState};
use rins::config::RinsConfig;
use rins::replay::input::{RawSample, ReplayInput};
use rins::replay::live::{self, LiveOptions, LiveOutput};
use rins::replay::offline::OfflinePipeline;
use rins_fusion::service::fused_message;
use rins_runtime::shutdown::Shutdown;

use super::progress::Progress;

pub use gnss_captures::{GnssLiveOptions, gnss_captures};
pub use pyshoe::pyshoe;
pub use quadrotor::{quadrotor_ahrs, quadrotor_gnss};

/// Where a live evaluation's configurations and deployment logs go: kept when the evaluation
/// fails, removed by [`Scratch::remove`] when it succeeds.
struct Scratch {
    dir: PathBuf,
}

impl Scratch {
    fn new() -> Result<Self> {
        let dir = std::env::temp_dir().join(format!("rins-eval-live-{}", std::process::id()));
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        Ok(Self { dir })
    }

    fn remove(self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Runs `run_one` on every recording of `recordings` in turn, under one progress bar (`label`)
/// over them all into which each recording's own progress is scaled; the results in order. The
/// scratch directory is removed when every one succeeded, and kept with its logs otherwise.
fn each_live<T, R>(
    label: &'static str,
    recordings: &[T],
    mut run_one: impl FnMut(&T, &Scratch, &mut dyn FnMut(usize, usize)) -> Result<R>,
) -> Result<Vec<R>> {
    let scratch = Scratch::new()?;
    let mut bar = Progress::new(label);
    let n = recordings.len();
    let mut results = Vec::with_capacity(n);
    for (k, recording) in recordings.iter().enumerate() {
        let mut progress =
            |done: usize, total: usize| bar.set(k * 1000 + done * 1000 / total.max(1), n * 1000);
        results.push(run_one(recording, &scratch, &mut progress)?);
    }
    bar.finish();
    scratch.remove();
    Ok(results)
}

/// `cfg` written out and read back as the deployment will read it (`what` names it in errors).
fn reparsed(cfg: &RinsConfig, what: &str) -> Result<RinsConfig> {
    let text = toml::to_string(cfg).with_context(|| format!("{what} does not serialise"))?;
    RinsConfig::parse(&text, what)
}

/// The sample index of each IMU frame's device time: its place among the IMU frames (other
/// samples between them not counted).
fn device_index(raw: &[RawSample]) -> HashMap<u64, usize> {
    raw.iter()
        .filter_map(|s| match s {
            RawSample::Imu(f) => Some(f.header.origin_device_time_us),
            _ => None,
        })
        .enumerate()
        .map(|(j, t)| (t, j))
        .collect()
}

/// The states of `states` that navigate (alignment left out), with the sample index of their
/// device time.
fn navigating<'a>(
    states: &'a [NavState],
    index: &'a HashMap<u64, usize>,
) -> impl Iterator<Item = (usize, &'a NavState)> + 'a {
    states
        .iter()
        .filter(|n| NavMode::from_u8(n.mode).is_some_and(|m| m != NavMode::Aligning))
        .filter_map(|n| Some((*index.get(&n.header.origin_device_time_us)?, n)))
}

/// `raw` through a fresh private deployment running `cfg`; its configuration and log are written
/// into `scratch` under `name`.
fn deploy(
    cfg: &RinsConfig,
    name: &str,
    raw: &[RawSample],
    scratch: &Scratch,
    shutdown: &Shutdown,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<LiveOutput> {
    let name = name.replace('/', "-");
    let config_file = scratch.dir.join(format!("{name}.toml"));
    std::fs::write(&config_file, toml::to_string(cfg)?)
        .with_context(|| format!("cannot write {}", config_file.display()))?;
    let options = LiveOptions {
        exe: None,
        config: Some(config_file),
        lanes: cfg.deployment.navigator_lanes,
        speed: None,
        log: Some(scratch.dir.join(format!("{name}.log"))),
        private: Some(live::private_settings("ev")?),
        gnss: false,
    };
    live::run(raw, &options, shutdown, progress)
}

/// The deployment's library code (fusion, altimeter, navigator lanes: `rins replay --offline`)
/// in this process, fed `raw`: each lane's states.
fn in_process(cfg: &RinsConfig, raw: &[RawSample]) -> Result<[Vec<NavState>; 2]> {
    let built = cfg.build_services()?;
    let input = ReplayInput {
        raw: raw.to_vec(),
        ..ReplayInput::default()
    };
    Ok(OfflinePipeline::new(
        built.fuser,
        built.altimeter,
        built.navigator,
        cfg.deployment.navigator_lanes,
    )
    .run(&input, |_| {}))
}

/// What fusion running `cfg` makes of each IMU frame of `raw`: the body rate (rad/s) and
/// specific force (m/s²) the navigator is fed.
fn fused(cfg: &RinsConfig, raw: &[RawSample]) -> Result<Vec<([f64; 3], [f64; 3])>> {
    let mut fuser = cfg.build_services()?.fuser;
    Ok(raw
        .iter()
        .filter_map(|s| match s {
            RawSample::Imu(raw) => Some(raw),
            _ => None,
        })
        .map(|raw| {
            let fused = fuser.fuse_raw(raw);
            let msg = fused_message(
                raw,
                &fused,
                usize::from(raw.n_gyro),
                usize::from(raw.n_accel),
            );
            (msg.rate_rps, msg.specific_force_mps2)
        })
        .collect())
}
