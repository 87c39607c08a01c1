//! `rins replay FILE`: the raw sensor topics of a recording fed through a fresh deployment —
//! fusion, the altimeter and the navigator lanes run live, as `rins up` starts them — and its
//! navigation output compared with the recorded one, sample for sample. `--offline` runs the same
//! library code in this process instead.

use std::process::ExitCode;
use std::time::Instant;

use anyhow::{Result, bail};

use ipc_types::NavState;
use rins::replay::compare::{NavComparison, compare};
use rins::replay::input::{RawSample, ReplayInput};
use rins::replay::live::{self, LiveOptions};
use rins::replay::offline::OfflinePipeline;
use rins_runtime::shutdown::Shutdown;
use serde::Serialize;

use crate::cli::ReplayArgs;
use crate::commands::progress::Progress;
use crate::config;

/// What `rins replay --json` prints last.
#[derive(Debug, Serialize)]
struct ReplayReport {
    file: String,
    mode: &'static str,
    raw_samples: u64,
    imu_frames: u64,
    seconds: f64,
    /// Recorded time over replay time.
    speed_achieved: f64,
    /// Navigation samples the replay produced, both lanes.
    nav_samples_replayed: u64,
    /// The file carries navigation output to compare with (a recording imported from another
    /// system's data, `rins import`, does not).
    recorded_navigation: bool,
    #[serde(flatten)]
    comparison: NavComparison,
    /// Aiding readings the recorded navigator lanes applied after their place in the IMU stream
    /// (a burst of frames after a serial stall); the replay applies them in their place, so the
    /// samples after the first cannot match.
    recorded_late_aiding: u64,
    /// Messages of the file that were skipped or not decodable.
    file_messages_skipped: u64,
    /// Chunks of the file skipped as damaged (their messages are lost, and not counted above).
    file_chunks_damaged: u64,
    file_damage: Option<String>,
}

pub fn run(args: &ReplayArgs) -> Result<ExitCode> {
    let speed = match (args.speed, args.as_fast_as_possible) {
        (Some(s), _) if !(s.is_finite() && s > 0.0) => {
            bail!("--speed {s}: must be a positive multiple of the recorded pace")
        }
        (Some(s), _) => Some(s),
        (None, true) => None,
        (None, false) => Some(1.0),
    };
    let mut cfg = config::load(args.config.as_deref())?;
    let input = ReplayInput::read(&args.file)?;
    // A recording with receiver fixes was made with the receiver on (`rins up --gnss`): the
    // navigator aids with them here too.
    let gnss = input.raw.iter().any(|s| matches!(s, RawSample::Gnss(_)));
    if gnss {
        cfg.enable_gnss();
    }
    if input.raw.is_empty() {
        bail!(
            "{}: no raw sensor samples to replay (record with the raw topics: rins record FILE)",
            args.file.display()
        );
    }
    let started = Instant::now();
    let (mode, replayed) = if args.offline {
        let built = cfg.build_services()?;
        let pipeline = OfflinePipeline::new(
            built.fuser,
            built.altimeter,
            built.navigator,
            cfg.deployment.navigator_lanes,
        );
        let mut progress = Progress::new("replaying offline");
        let out = pipeline.run(&input, |share| {
            progress.set((share * 1000.0) as usize, 1000)
        });
        progress.finish();
        ("offline", out)
    } else {
        (
            "live",
            replay_live(args, &input, speed, cfg.deployment.navigator_lanes, gnss)?,
        )
    };
    let seconds = started.elapsed().as_secs_f64();
    let span_s = recorded_span_s(&input);
    let report = ReplayReport {
        file: args.file.display().to_string(),
        mode,
        raw_samples: input.raw.len() as u64,
        imu_frames: input.imu_frames() as u64,
        seconds,
        speed_achieved: if seconds > 0.0 { span_s / seconds } else { 0.0 },
        nav_samples_replayed: replayed.iter().map(|lane| lane.len() as u64).sum(),
        recorded_navigation: input.nav.iter().any(|lane| !lane.is_empty()),
        comparison: compare(&input.nav, &replayed),
        recorded_late_aiding: input.recorded_late_aiding.iter().sum(),
        file_messages_skipped: input.skipped + input.undecodable,
        file_chunks_damaged: input.damaged_chunks,
        file_damage: input.damage.clone(),
    };
    let c = &report.comparison;
    if args.json {
        println!("{}", serde_json::to_string(&report)?);
    } else {
        println!(
            "{}: {} raw samples replayed {} in {:.1} s ({:.1}× the recorded pace); navigation: {} \
             samples compared, {} different, {} missing",
            report.file,
            report.raw_samples,
            mode,
            seconds,
            report.speed_achieved,
            c.nav_samples_compared,
            c.nav_samples_different,
            c.nav_samples_missing
        );
        if !report.recorded_navigation {
            println!(
                "{}: no recorded navigation output to compare with; the replay produced {} \
                 navigation samples",
                report.file, report.nav_samples_replayed
            );
        }
        if report.file_chunks_damaged > 0 || report.file_messages_skipped > 0 {
            println!(
                "{}: {} damaged chunks and {} damaged messages skipped",
                report.file, report.file_chunks_damaged, report.file_messages_skipped
            );
        }
        if let Some(damage) = &report.file_damage {
            println!("{}: reading stopped early: {damage}", report.file);
        }
        if report.recorded_late_aiding > 0 && c.nav_samples_different > 0 {
            println!(
                "the recording's navigator applied {} aiding readings after their place in the IMU \
                 stream (a burst of frames after a serial stall); the replay applies them in their \
                 place, so the samples after the first of them differ",
                report.recorded_late_aiding
            );
        }
    }
    // Not identical is a finding a script must see; so is a file with nothing to compare that
    // produced no navigation.
    let passed = if report.recorded_navigation {
        c.nav_samples_different == 0 && c.nav_samples_compared > 0
    } else {
        report.nav_samples_replayed > 0
    };
    Ok(if passed {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

/// Recorded time from the first raw sample to the last, s.
fn recorded_span_s(input: &ReplayInput) -> f64 {
    let times = input.raw.iter().map(RawSample::rx_ns);
    let (lo, hi) = times.fold((u64::MAX, 0), |(lo, hi), t| (lo.min(t), hi.max(t)));
    hi.saturating_sub(lo) as f64 * 1e-9
}

fn replay_live(
    args: &ReplayArgs,
    input: &ReplayInput,
    speed: Option<f64>,
    lanes: u8,
    gnss: bool,
) -> Result<[Vec<NavState>; 2]> {
    let shutdown = Shutdown::install()?;
    let options = LiveOptions {
        exe: None,
        config: args.config.clone(),
        lanes,
        speed,
        private: None,
        log: None,
        gnss,
    };
    let mut progress = Progress::new("replaying");
    let out = live::run(&input.raw, &options, &shutdown, &mut |done, total| {
        progress.set(done, total)
    })?;
    progress.finish();
    Ok(out.nav)
}
