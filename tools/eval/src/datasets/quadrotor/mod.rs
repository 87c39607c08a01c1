//! The four-IMU quadrotor data set (Hurwitz & Klein 2023, CC BY 4.0): a DJI Phantom 4 carrying
//! four Xsens DOT IMUs, with RTK ground truth.
//!
//! Layout: `<group>/path_<N>/{IMU_1..4.csv, GT.csv}` with groups `Horizontal` and `StraightLine`
//! (the copy at hand has 8 + 4 trials, all with four IMUs; the published set also has vertical
//! trials, some with a single IMU: a missing or unusable IMU file is skipped with a note, a trial
//! without any usable IMU or without truth is an error). Defects of the time column are repaired
//! and counted (see [`repair`]). IMU files: time s, Euler_X/Y/Z °, Acc_X/Y/Z m/s²,
//! Gyr_X/Y/Z °/s at 120 Hz. GT.csv at 10 Hz: time, distance, speed, compass heading °, pitch °,
//! roll °, height above take-off m, North, East, Down m.
//!
//! Loaded trials are in SI units and FRD axes (see [`frame`]), the IMUs aligned on one time base
//! (see [`align`]) and the truth moved onto it (see [`clock`]).

pub mod align;
pub mod clock;
pub mod frame;
pub mod lever_arm;
mod load;
pub mod projection;
pub mod repair;
pub mod subrow;

use std::path::{Path, PathBuf};

use serde::Serialize;

use super::error::DatasetError;
pub use load::load_trial;
pub use repair::Repairs;

/// IMU output rate, Hz.
pub const IMU_RATE_HZ: f64 = 120.0;
/// Ground-truth rate, Hz.
pub const TRUTH_RATE_HZ: f64 = 10.0;
/// IMU files a trial may hold (`IMU_1.csv` … `IMU_4.csv`).
pub const MAX_IMUS: usize = 4;
/// Fewest rows an IMU file must have (1 s).
pub const MIN_IMU_ROWS: usize = 120;
/// Fewest rows the truth file must have (1 s).
pub const MIN_TRUTH_ROWS: usize = 10;

pub(crate) const IMU_HEADER: [&str; 10] = [
    "time", "Euler_X", "Euler_Y", "Euler_Z", "Acc_X", "Acc_Y", "Acc_Z", "Gyr_X", "Gyr_Y", "Gyr_Z",
];
pub(crate) const TRUTH_HEADER: [&str; 10] = [
    "time",
    "distance(meters)",
    "speed(m/s)",
    "compass_heading(degrees)",
    "pitch(degrees)",
    "roll(degrees)",
    "height_above_takeoff(meters)",
    "North",
    "East",
    "Down",
];

/// One IMU sample in SI units and FRD axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// Time on the trial's common time base (the reference IMU's clock), s.
    pub t_s: f64,
    /// Body rate, FRD, rad/s.
    pub gyro_rps: [f64; 3],
    /// Specific force, FRD, m/s².
    pub accel_mps2: [f64; 3],
    /// The unit's own attitude estimate as FRD roll, pitch, yaw (rad); yaw has an arbitrary,
    /// per-unit offset (see [`frame`]).
    pub euler_rad: [f64; 3],
}

/// One IMU of a trial, aligned on the common time base.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuSeries {
    /// The number in the file name (`IMU_<imu>.csv`).
    pub imu: usize,
    /// Rows this unit's data lags the reference IMU (positive: it records the same motion later);
    /// sample j of every series in the trial is the same instant.
    pub lag_rows: i64,
    /// Smallest and largest residual lag (rows, fractional) removed by resampling after the
    /// whole-row alignment (see [`subrow`]); zero for the reference.
    pub residual_lag_rows: [f64; 2],
    /// What was repaired in the file's rows ([`repair`]).
    pub repairs: Repairs,
    /// Added to the truth file's times to put them on this unit file's own time column, s: the
    /// trial's [`Trial::truth_offset_s`] plus this unit's whole-row and mean residual lag.
    pub truth_offset_s: f64,
    /// The aligned samples; every series of a trial has the same length and times.
    pub samples: Vec<ImuSample>,
}

impl ImuSeries {
    /// Unit `imu` recording `samples` on the reference's rows: no lag, nothing repaired, the
    /// truth on the same clock. A test fixture.
    #[cfg(test)]
    pub(crate) fn aligned(imu: usize, samples: Vec<ImuSample>) -> Self {
        Self {
            imu,
            lag_rows: 0,
            residual_lag_rows: [0.0; 2],
            repairs: Repairs::default(),
            truth_offset_s: 0.0,
            samples,
        }
    }
}

/// One ground-truth row in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthRow {
    /// Time on the IMU time base (file time + [`Trial::truth_offset_s`]), s.
    pub t_s: f64,
    /// Distance flown, m.
    pub distance_m: f64,
    /// Ground speed, m/s.
    pub speed_mps: f64,
    /// Compass heading, rad.
    pub heading_rad: f64,
    /// Pitch, rad.
    pub pitch_rad: f64,
    /// Roll, rad.
    pub roll_rad: f64,
    /// Height above the take-off point, m.
    pub height_m: f64,
    /// Position north of the first row, m.
    pub north_m: f64,
    /// Position east of the first row, m.
    pub east_m: f64,
    /// Position down from the first row, m.
    pub down_m: f64,
}

/// One recorded flight.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// `<group>/path_<N>`, e.g. `Horizontal/path_1`.
    pub name: String,
    /// Directory of the trial.
    pub path: PathBuf,
    /// The IMUs present, in file-number order; the first is the reference of the time base.
    pub imus: Vec<ImuSeries>,
    /// Ground truth on the IMU time base.
    pub truth: Vec<TruthRow>,
    /// Added to the truth file's times to put them on the IMU time base, s.
    pub truth_offset_s: f64,
    /// What was repaired over the trial's units, and the unit files skipped.
    pub repairs: Repairs,
    /// What the loader noticed: missing or skipped IMU files, lags, repairs, trimmed rows.
    pub notes: Vec<String>,
}

impl Trial {
    /// A trial named "synthetic" of the units `imus`, without truth, repairs or notes. A test
    /// fixture.
    #[cfg(test)]
    pub(crate) fn synthetic(imus: Vec<ImuSeries>) -> Self {
        Self {
            name: "synthetic".into(),
            path: "synthetic".into(),
            imus,
            truth: Vec::new(),
            truth_offset_s: 0.0,
            repairs: Repairs::default(),
            notes: Vec::new(),
        }
    }

    /// Number of aligned samples (the same for every IMU).
    pub fn len(&self) -> usize {
        self.imus.first().map_or(0, |s| s.samples.len())
    }

    /// True when there are no aligned samples.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A trial directory found by [`list_trials`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrialEntry {
    /// `<group>/path_<N>`.
    pub name: String,
    /// Directory of the trial.
    pub path: PathBuf,
    /// IMU file numbers present.
    pub imus: Vec<usize>,
    /// `GT.csv` is present.
    pub has_truth: bool,
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> DatasetError + '_ {
    move |source| DatasetError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The number N of a `path_N` directory name.
fn path_number(name: &str) -> Option<u32> {
    name.strip_prefix("path_")?.parse().ok()
}

/// Every `<group>/path_<N>` directory under `dir`, sorted by group then N.
pub fn list_trials(dir: &Path) -> Result<Vec<TrialEntry>, DatasetError> {
    let mut trials = Vec::new();
    let mut groups: Vec<_> = std::fs::read_dir(dir)
        .map_err(io_error(dir))?
        .filter_map(Result::ok)
        .filter(|e| e.path().is_dir())
        .collect();
    groups.sort_by_key(|e| e.file_name());
    for group in groups {
        let group_path = group.path();
        let mut paths: Vec<(u32, PathBuf, String)> = std::fs::read_dir(&group_path)
            .map_err(io_error(&group_path))?
            .filter_map(Result::ok)
            .filter(|e| e.path().is_dir())
            .filter_map(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                path_number(&name).map(|n| (n, e.path(), name))
            })
            .collect();
        paths.sort();
        for (_, path, name) in paths {
            trials.push(TrialEntry {
                name: format!("{}/{name}", group.file_name().to_string_lossy()),
                imus: (1..=MAX_IMUS)
                    .filter(|k| path.join(format!("IMU_{k}.csv")).is_file())
                    .collect(),
                has_truth: path.join("GT.csv").is_file(),
                path,
            });
        }
    }
    Ok(trials)
}

/// Trial name from its directory: the last two components.
fn trial_name(path: &Path) -> String {
    let mut parts: Vec<String> = path
        .components()
        .rev()
        .take(2)
        .map(|c| c.as_os_str().to_string_lossy().into_owned())
        .collect();
    parts.reverse();
    parts.join("/")
}

/// A trial that could not be used, and why: listed in the evaluations' reports.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct SkippedTrial {
    /// `<group>/path_<N>`.
    pub trial: String,
    /// Why it was skipped.
    pub reason: String,
}

/// The lines of a report listing skipped trials (none when nothing was skipped).
pub fn skipped_lines(skipped: &[SkippedTrial]) -> String {
    if skipped.is_empty() {
        return String::new();
    }
    let mut s = format!("{} trials skipped:\n", skipped.len());
    for t in skipped {
        s.push_str(&format!("  {}: {}\n", t.trial, t.reason));
    }
    s
}

/// The error of an evaluation that could use none of the trials it found: every reason, so the
/// operator sees which file to look at.
pub fn nothing_evaluated(skipped: &[SkippedTrial]) -> String {
    let reasons: Vec<String> = skipped
        .iter()
        .map(|t| format!("{}: {}", t.trial, t.reason))
        .collect();
    format!("no trial could be evaluated ({})", reasons.join("; "))
}

/// One listed trial and what loading it gave.
pub type Outcome = (TrialEntry, Result<Trial, DatasetError>);

/// Loads every trial under `dir`, each on its own: every listed trial with either the loaded
/// trial or the error that names why it could not be. `progress(done, total)` after each. Only
/// a directory that cannot be listed is an error.
pub fn load_each(
    dir: &Path,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<Outcome>, DatasetError> {
    let entries = list_trials(dir)?;
    let total = entries.len();
    progress(0, total);
    let mut out = Vec::with_capacity(total);
    for (k, entry) in entries.into_iter().enumerate() {
        let trial = load_trial(&entry.path);
        out.push((entry, trial));
        progress(k + 1, total);
    }
    Ok(out)
}

/// The repairs over every outcome of [`load_each`], counting the trials that failed.
pub fn total_repairs(outcomes: &[Outcome]) -> Repairs {
    outcomes
        .iter()
        .fold(Repairs::default(), |total, (_, outcome)| match outcome {
            Ok(trial) => total + trial.repairs,
            Err(_) => {
                total
                    + Repairs {
                        trials_failed: 1,
                        ..Repairs::default()
                    }
            }
        })
}

/// Loads every trial under `dir`; `progress(done, total)` after each. The first trial that
/// cannot be loaded is an error naming its file (see [`load_each`] to keep the others).
pub fn load_all(
    dir: &Path,
    progress: impl FnMut(usize, usize),
) -> Result<Vec<Trial>, DatasetError> {
    load_each(dir, progress)?
        .into_iter()
        .map(|(_, trial)| trial)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_numbers() {
        assert_eq!(path_number("path_12"), Some(12));
        assert_eq!(path_number("path_x"), None);
        assert_eq!(path_number("paths_1"), None);
        assert_eq!(
            trial_name(Path::new("/data/quadrotor/Horizontal/path_3")),
            "Horizontal/path_3"
        );
    }
}
