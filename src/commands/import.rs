//! `rins import`: the public recordings the evaluations run on, written as rins recordings (raw
//! IMU frames and truth in MCAP, as `rins record` writes them), each with its configuration
//! (`.toml`) and what the loader found (`.json`: clock offsets, repairs, scales) beside it.
//!
//! A trial the loader or the conversion cannot use is skipped and listed with the reason; only a
//! data set directory that cannot be listed, an output that already exists (without `--force`)
//! or a file that cannot be written stops the import.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, anyhow, bail};
use ipc_types::{RawImu, Truth, names};
use rins_eval::datasets::quadrotor::SkippedTrial;
use rins_eval::import::quadrotor::Profile;
use rins_eval::import::{ClockOffset, ImportedRun, Quantisation, RepairCount, Scales};
use rins_recording::{RecordOptions, Recorder, create_file};
use serde::Serialize;

use crate::cli::ImportArgs;
use crate::config::{self, RinsConfig};

/// One run to import: its name, where it comes from, and the output path without extension.
struct Planned {
    name: String,
    source: PathBuf,
    stem: PathBuf,
}

impl Planned {
    /// The stem with `.extension` appended (a run name may hold dots of its own).
    fn output(&self, extension: &str) -> PathBuf {
        let mut path = self.stem.clone().into_os_string();
        path.push(".");
        path.push(extension);
        path.into()
    }

    fn outputs(&self) -> [PathBuf; 3] {
        ["mcap", "toml", "json"].map(|e| self.output(e))
    }
}

/// One run written.
#[derive(Debug, Serialize)]
struct Written {
    name: String,
    recording: PathBuf,
    config: PathBuf,
    sidecar: PathBuf,
    channels: u8,
    imu_frames: usize,
    truth_samples: usize,
    duration_s: f64,
    rate_hz: f64,
    scales: Scales,
    quantisation: Quantisation,
    file_bytes: u64,
}

/// What `rins import` did.
#[derive(Debug, Serialize)]
struct Summary {
    data_set: &'static str,
    dir: PathBuf,
    out: PathBuf,
    written: Vec<Written>,
    skipped: Vec<SkippedTrial>,
    /// Repairs over the written runs, by kind; trials skipped count as `trials_skipped`.
    repairs: BTreeMap<String, usize>,
    /// Configurations written that the configuration loader refuses (the file names itself).
    config_errors: Vec<String>,
}

/// The `.json` beside a recording.
#[derive(Debug, Serialize)]
struct Sidecar<'a> {
    name: &'a str,
    source: &'a Path,
    recording: &'a Path,
    config: &'a Path,
    rate_hz: f64,
    channels: u8,
    imu_frames: usize,
    truth_samples: usize,
    scales: &'a Scales,
    quantisation: &'a Quantisation,
    clock_offsets: &'a [ClockOffset],
    repairs: &'a [RepairCount],
    notes: &'a [String],
}

fn require_dir(what: &str, dir: &Path) -> Result<()> {
    if dir.is_dir() {
        Ok(())
    } else {
        bail!(
            "import {what}: data set directory {} does not exist or is not a directory; {}",
            dir.display(),
            rins_eval::data::fetch_hint(dir)
        )
    }
}

/// Refuses, before anything is written, outputs that already exist (unless `force`).
fn check_outputs(what: &str, planned: &[Planned], force: bool) -> Result<()> {
    if force {
        return Ok(());
    }
    let existing: Vec<PathBuf> = planned
        .iter()
        .flat_map(Planned::outputs)
        .filter(|p| std::fs::symlink_metadata(p).is_ok())
        .collect();
    match existing.first() {
        None => Ok(()),
        Some(first) => bail!(
            "import {what}: {} exists ({} output files in all): give --force to replace them",
            first.display(),
            existing.len()
        ),
    }
}

fn write_text(path: &Path, text: &str, force: bool) -> Result<()> {
    let mut file = create_file(path, force)?;
    file.write_all(text.as_bytes())
        .and_then(|()| file.sync_all())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// The raw IMU frames and the truth, merged in device-time order (a frame before the truth of
/// the same instant), written as `rins record` writes them: log time the frame's receive time.
fn write_recording(path: &Path, run: &ImportedRun, force: bool) -> Result<u64> {
    let options = RecordOptions {
        overwrite: force,
        ..RecordOptions::default()
    };
    let mut rec = Recorder::create(path, &options)?;
    let imu_channel = rec.channel_for::<RawImu>(names::RAW_IMU)?;
    let truth_channel = rec.channel_for::<Truth>(names::TRUTH)?;
    let mut truth = run.truth.iter().peekable();
    for frame in &run.imu {
        let t = frame.header.origin_device_time_us;
        while let Some(sample) = truth.next_if(|s| s.header.origin_device_time_us < t) {
            let ns = rins_eval::import::rx_ns(sample.header.origin_device_time_us);
            rec.write_payload(truth_channel, ns, ns, sample)?;
        }
        let ns = frame.header.origin_rx_ns;
        rec.write_payload(imu_channel, ns, ns, frame)?;
    }
    for sample in truth {
        let ns = rins_eval::import::rx_ns(sample.header.origin_device_time_us);
        rec.write_payload(truth_channel, ns, ns, sample)?;
    }
    Ok(rec.finish()?.file_bytes)
}

/// Writes one run's three files; the configuration loader's objection, if any, is returned.
fn write_run(
    planned: &Planned,
    run: &ImportedRun,
    force: bool,
) -> Result<(Written, Option<String>)> {
    let [recording, config_path, sidecar_path] = planned.outputs();
    if let Some(parent) = recording.parent() {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("cannot create {}", parent.display()))?;
    }
    let file_bytes = write_recording(&recording, run, force)?;
    write_text(&config_path, &run.config_fragment, force)?;
    let config_error = RinsConfig::parse(&run.config_fragment, &config_path.display().to_string())
        .err()
        .map(|e| format!("{e:#}"));
    let channels = run.imu.first().map_or(0, |f| f.n_gyro);
    let sidecar = Sidecar {
        name: &run.name,
        source: &planned.source,
        recording: &recording,
        config: &config_path,
        rate_hz: run.rate_hz,
        channels,
        imu_frames: run.imu.len(),
        truth_samples: run.truth.len(),
        scales: &run.scales,
        quantisation: &run.quantisation,
        clock_offsets: &run.clock_offsets,
        repairs: &run.repairs,
        notes: &run.notes,
    };
    write_text(
        &sidecar_path,
        &(serde_json::to_string_pretty(&sidecar)? + "\n"),
        force,
    )?;
    let device_s =
        |f: Option<&RawImu>| f.map_or(0.0, |f| f.header.origin_device_time_us as f64 / 1e6);
    Ok((
        Written {
            name: run.name.clone(),
            recording,
            config: config_path,
            sidecar: sidecar_path,
            channels,
            imu_frames: run.imu.len(),
            truth_samples: run.truth.len(),
            duration_s: device_s(run.imu.last()) - device_s(run.imu.first()),
            rate_hz: run.rate_hz,
            scales: run.scales,
            quantisation: run.quantisation,
            file_bytes,
        },
        config_error,
    ))
}

/// Imports every planned run with `import` (load and convert; the error says why, naming the
/// file), writes the files, prints the summary.
fn import_all(
    what: &'static str,
    args: &ImportArgs,
    planned: Vec<Planned>,
    import: impl Fn(&Planned) -> Result<ImportedRun>,
) -> Result<ExitCode> {
    check_outputs(what, &planned, args.force)?;
    let mut summary = Summary {
        data_set: what,
        dir: args.dir.clone(),
        out: args.out.clone(),
        written: Vec::new(),
        skipped: Vec::new(),
        repairs: BTreeMap::new(),
        config_errors: Vec::new(),
    };
    let mut bar = super::progress::Progress::new(match what {
        "quadrotor" => "import quadrotor",
        _ => "import pyshoe",
    });
    let total = planned.len();
    bar.set(0, total);
    for (k, p) in planned.iter().enumerate() {
        match import(p) {
            Ok(run) => {
                for r in &run.repairs {
                    *summary.repairs.entry(r.kind.clone()).or_default() += r.count;
                }
                let (written, config_error) = write_run(p, &run, args.force)?;
                summary.written.push(written);
                summary.config_errors.extend(config_error);
            }
            Err(e) => {
                *summary.repairs.entry("trials_skipped".into()).or_default() += 1;
                summary.skipped.push(SkippedTrial {
                    trial: p.name.clone(),
                    reason: format!("{e:#}"),
                });
            }
        }
        bar.set(k + 1, total);
    }
    bar.finish();
    if args.json {
        println!("{}", serde_json::to_string(&summary)?);
    } else {
        print!("{}", summary_text(&summary));
    }
    if summary.written.is_empty() {
        return Err(anyhow!(
            "import {what}: no run could be imported from {}",
            args.dir.display()
        ));
    }
    Ok(if summary.config_errors.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

fn summary_text(s: &Summary) -> String {
    let mut out = format!(
        "import {}: {} runs written to {}, {} skipped\n",
        s.data_set,
        s.written.len(),
        s.out.display(),
        s.skipped.len()
    );
    for w in &s.written {
        out += &format!(
            "  {}: {} channels, {} frames at {} Hz ({:.1} s), {} truth; full scale {} °/s, {} g; \
             quantisation ≤ {:.2e} °/s, {:.2e} m/s²\n",
            w.name,
            w.channels,
            w.imu_frames,
            w.rate_hz,
            w.duration_s,
            w.truth_samples,
            w.scales.gyro_full_scale_dps,
            w.scales.accel_full_scale_g,
            w.quantisation.gyro_max_error_rps.to_degrees(),
            w.quantisation.accel_max_error_mps2,
        );
    }
    if !s.repairs.is_empty() {
        let kinds: Vec<String> = s.repairs.iter().map(|(k, n)| format!("{k} {n}")).collect();
        out += &format!("repairs: {}\n", kinds.join(", "));
    }
    for t in &s.skipped {
        out += &format!("skipped {}: {}\n", t.trial, t.reason);
    }
    for e in &s.config_errors {
        out += &format!("configuration refused: {e}\n");
    }
    out
}

/// The profile's text, name and the navigator origin it configures.
fn profile(text: &'static str, name: &'static str) -> Result<Profile<'static>> {
    let cfg = RinsConfig::parse(text, name)?;
    Ok(Profile {
        text,
        name,
        origin: cfg.navigator.aided_config().origin,
    })
}

/// `rins import quadrotor DIR OUT`.
pub fn run_quadrotor(args: &ImportArgs) -> Result<ExitCode> {
    use rins_eval::datasets::quadrotor::{list_trials, load_trial};
    require_dir("quadrotor", &args.dir)?;
    let entries = list_trials(&args.dir)
        .with_context(|| format!("import quadrotor: cannot list {}", args.dir.display()))?;
    if entries.is_empty() {
        bail!(
            "import quadrotor: no trials (<group>/path_<N>/IMU_k.csv) in {}",
            args.dir.display()
        );
    }
    let profile = profile(config::UAV, "built-in uav profile (config/uav.toml)")?;
    let planned = entries
        .into_iter()
        .map(|e| Planned {
            stem: args.out.join(&e.name),
            name: e.name,
            source: e.path,
        })
        .collect();
    import_all("quadrotor", args, planned, |p| {
        let trial = load_trial(&p.source)?;
        rins_eval::import::quadrotor::import_trial(&trial, &profile)
    })
}

/// `rins import pyshoe DIR OUT`.
pub fn run_pyshoe(args: &ImportArgs) -> Result<ExitCode> {
    use rins_eval::datasets::pyshoe::{list_trials, load_trial};
    require_dir("pyshoe", &args.dir)?;
    let files = list_trials(&args.dir)
        .with_context(|| format!("import pyshoe: cannot list {}", args.dir.display()))?;
    if files.is_empty() {
        bail!("import pyshoe: no trials (*.csv) in {}", args.dir.display());
    }
    let profile = profile(
        config::PEDESTRIAN,
        "built-in pedestrian profile (config/pedestrian.toml)",
    )?;
    let planned = files
        .into_iter()
        .map(|path| {
            let name = path
                .file_stem()
                .map_or_else(String::new, |s| s.to_string_lossy().into_owned());
            Planned {
                stem: args.out.join(&name),
                name,
                source: path,
            }
        })
        .collect();
    import_all("pyshoe", args, planned, |p| {
        let trial = load_trial(&p.source)?;
        rins_eval::import::pyshoe::import_trial(&trial, &profile)
    })
}
