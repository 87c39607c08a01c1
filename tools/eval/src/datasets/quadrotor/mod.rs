//! The four-IMU quadrotor data set (Hurwitz & Klein 2023, CC BY 4.0): a DJI Phantom 4 carrying
//! four Xsens DOT IMUs, with RTK ground truth.
//!
//! Layout: `<group>/path_<N>/{IMU_1..4.csv, GT.csv}` with groups `Horizontal` and `StraightLine`
//! (the copy at hand has 8 + 4 trials, all with four IMUs; the published set also has vertical
//! trials, some with a single IMU: a missing IMU file is skipped with a note, a trial without any
//! IMU or without truth is an error). IMU files: time s, Euler_X/Y/Z °, Acc_X/Y/Z m/s²,
//! Gyr_X/Y/Z °/s at 120 Hz. GT.csv at 10 Hz: time, distance, speed, compass heading °, pitch °,
//! roll °, height above take-off m, North, East, Down m.
//!
//! Loaded trials are in SI units and FRD axes (see [`frame`]), the IMUs aligned on one time base
//! and the truth moved onto it (see [`align`]).

pub mod align;
pub mod frame;
pub mod lever_arm;
pub mod projection;
pub mod subrow;

use std::path::{Path, PathBuf};

use super::csv::read_numeric;
use super::error::DatasetError;

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

const IMU_HEADER: [&str; 10] = [
    "time", "Euler_X", "Euler_Y", "Euler_Z", "Acc_X", "Acc_Y", "Acc_Z", "Gyr_X", "Gyr_Y", "Gyr_Z",
];
const TRUTH_HEADER: [&str; 10] = [
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
    /// Rows of the file whose timestamp step is not one period (repeated or skipped timestamps).
    pub timestamp_glitches: usize,
    /// The aligned samples; every series of a trial has the same length and times.
    pub samples: Vec<ImuSample>,
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
    /// What the loader noticed: missing IMU files, lags, timestamp glitches, trimmed rows.
    pub notes: Vec<String>,
}

impl Trial {
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

/// One IMU file as read: times, and samples converted to SI/FRD.
struct RawImu {
    imu: usize,
    times: Vec<f64>,
    samples: Vec<ImuSample>,
    glitches: usize,
}

fn read_imu(path: &Path, imu: usize) -> Result<RawImu, DatasetError> {
    let rows = read_numeric(path, &IMU_HEADER)?;
    if rows.len() < MIN_IMU_ROWS {
        return Err(DatasetError::TooShort {
            path: path.to_path_buf(),
            rows: rows.len(),
            min: MIN_IMU_ROWS,
        });
    }
    let period = 1.0 / IMU_RATE_HZ;
    let mut glitches = 0;
    for (k, pair) in rows.windows(2).enumerate() {
        let step = pair[1][0] - pair[0][0];
        if step < -0.5 * period {
            return Err(DatasetError::Malformed {
                path: path.to_path_buf(),
                line: k + 3,
                reason: format!("time {} goes back from {}", pair[1][0], pair[0][0]),
            });
        }
        if (step - period).abs() > 0.25 * period {
            glitches += 1;
        }
    }
    let samples = rows
        .iter()
        .map(|r| ImuSample {
            t_s: r[0],
            gyro_rps: frame::xsens_to_frd([r[7], r[8], r[9]].map(f64::to_radians)),
            accel_mps2: frame::xsens_to_frd([r[4], r[5], r[6]]),
            euler_rad: frame::xsens_euler_to_frd([r[1], r[2], r[3]]),
        })
        .collect();
    Ok(RawImu {
        imu,
        times: rows.iter().map(|r| r[0]).collect(),
        samples,
        glitches,
    })
}

fn read_truth(path: &Path) -> Result<Vec<TruthRow>, DatasetError> {
    let rows = read_numeric(path, &TRUTH_HEADER)?;
    if rows.len() < MIN_TRUTH_ROWS {
        return Err(DatasetError::TooShort {
            path: path.to_path_buf(),
            rows: rows.len(),
            min: MIN_TRUTH_ROWS,
        });
    }
    Ok(rows
        .iter()
        .map(|r| TruthRow {
            t_s: r[0],
            distance_m: r[1],
            speed_mps: r[2],
            heading_rad: r[3].to_radians(),
            pitch_rad: r[4].to_radians(),
            roll_rad: r[5].to_radians(),
            height_m: r[6],
            north_m: r[7],
            east_m: r[8],
            down_m: r[9],
        })
        .collect())
}

fn rate_magnitude(samples: &[ImuSample]) -> Vec<f64> {
    samples
        .iter()
        .map(|s| s.gyro_rps.iter().map(|x| x * x).sum::<f64>().sqrt())
        .collect()
}

/// Loads one trial directory: every `IMU_k.csv` present (k = 1..=4), aligned on the first one's
/// time base, and `GT.csv` moved onto it. Missing IMU files are noted, not fatal.
pub fn load_trial(path: &Path) -> Result<Trial, DatasetError> {
    let name = trial_name(path);
    let mut notes = Vec::new();
    let mut raw = Vec::new();
    for imu in 1..=MAX_IMUS {
        let file = path.join(format!("IMU_{imu}.csv"));
        if file.is_file() {
            raw.push(read_imu(&file, imu)?);
        } else {
            notes.push(format!("IMU_{imu}.csv missing: skipped"));
        }
    }
    let Some(reference) = raw.first() else {
        return Err(DatasetError::MissingFile {
            path: path.join("IMU_1.csv"),
            what: "no IMU_1..4.csv in the trial",
        });
    };
    let truth_path = path.join("GT.csv");
    if !truth_path.is_file() {
        return Err(DatasetError::MissingFile {
            path: truth_path,
            what: "ground truth",
        });
    }
    let mut truth = read_truth(&truth_path)?;

    // Lag of each IMU against the reference, on the rate magnitude (mounting-independent).
    let reference_rate = rate_magnitude(&reference.samples);
    let mut lags: Vec<i64> = Vec::with_capacity(raw.len());
    for series in &raw {
        if series.imu == reference.imu {
            lags.push(0);
            continue;
        }
        let lag = align::estimate_lag(
            &reference_rate,
            &rate_magnitude(&series.samples),
            align::MAX_LAG_ROWS,
        )
        .ok_or_else(|| DatasetError::Mismatch {
            trial: name.clone(),
            reason: format!(
                "IMU_{} ({} rows) does not overlap IMU_{} ({} rows)",
                series.imu,
                series.samples.len(),
                reference.imu,
                reference.samples.len()
            ),
        })?;
        lags.push(lag);
    }
    // Common rows j of the reference such that j + lag is inside every series.
    let start = lags.iter().map(|&l| (-l).max(0)).max().unwrap_or(0) as usize;
    let end = raw
        .iter()
        .zip(&lags)
        .map(|(s, &l)| (s.samples.len() as i64 - l).max(0) as usize)
        .min()
        .unwrap_or(0)
        .min(reference.samples.len());
    if end <= start + MIN_IMU_ROWS {
        return Err(DatasetError::Mismatch {
            trial: name,
            reason: format!(
                "aligned IMUs overlap on {} rows only",
                end.saturating_sub(start)
            ),
        });
    }
    let times: Vec<f64> = reference.times[start..end].to_vec();
    let imus: Vec<ImuSeries> = raw
        .iter()
        .zip(&lags)
        .map(|(series, &lag)| {
            let from = (start as i64 + lag) as usize;
            let samples = series.samples[from..from + times.len()]
                .iter()
                .zip(&times)
                .map(|(s, &t_s)| ImuSample { t_s, ..*s })
                .collect();
            if lag != 0 {
                notes.push(format!(
                    "IMU_{} lags IMU_{} by {lag} rows",
                    series.imu, reference.imu
                ));
            }
            if series.glitches > 0 {
                notes.push(format!(
                    "IMU_{}: {} timestamp steps are not one period (data kept on the row grid)",
                    series.imu, series.glitches
                ));
            }
            ImuSeries {
                imu: series.imu,
                lag_rows: lag,
                residual_lag_rows: [0.0; 2],
                timestamp_glitches: series.glitches,
                samples,
            }
        })
        .collect();
    let mut imus = imus;
    let reference_rate = rate_magnitude(&imus[0].samples);
    for series in imus.iter_mut().skip(1) {
        let lag = subrow::residual_lag(&reference_rate, &rate_magnitude(&series.samples));
        let lo = lag.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = lag.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        series.samples = subrow::resample(&series.samples, &lag);
        series.residual_lag_rows = [lo, hi];
        notes.push(format!(
            "IMU_{}: residual lag {lo:+.2}..{hi:+.2} rows removed by resampling",
            series.imu
        ));
    }
    let trimmed = reference.samples.len() - times.len();
    if trimmed > 0 {
        notes.push(format!(
            "{trimmed} reference rows trimmed to the common span"
        ));
    }

    // Truth clock against the reference IMU's roll and pitch.
    let (roll, pitch): (Vec<f64>, Vec<f64>) = imus[0]
        .samples
        .iter()
        .map(|s| (s.euler_rad[0], s.euler_rad[1]))
        .unzip();
    let truth_angles: Vec<(f64, f64, f64)> = truth
        .iter()
        .map(|r| (r.t_s, r.roll_rad, r.pitch_rad))
        .collect();
    let truth_offset_s = align::estimate_truth_offset(
        &truth_angles,
        &roll,
        &pitch,
        times[0],
        1.0 / IMU_RATE_HZ,
        align::MAX_TRUTH_OFFSET_S,
        1.0 / IMU_RATE_HZ,
    )
    .unwrap_or_else(|| {
        notes.push("truth clock offset not estimable: kept at 0".into());
        0.0
    });
    truth.iter_mut().for_each(|r| r.t_s += truth_offset_s);

    Ok(Trial {
        name,
        path: path.to_path_buf(),
        imus,
        truth,
        truth_offset_s,
        notes,
    })
}

/// Loads every trial under `dir`; `progress(done, total)` after each. A trial that cannot be
/// loaded is an error naming its file.
pub fn load_all(
    dir: &Path,
    mut progress: impl FnMut(usize, usize),
) -> Result<Vec<Trial>, DatasetError> {
    let entries = list_trials(dir)?;
    let total = entries.len();
    progress(0, total);
    let mut trials = Vec::with_capacity(total);
    for (k, entry) in entries.iter().enumerate() {
        trials.push(load_trial(&entry.path)?);
        progress(k + 1, total);
    }
    Ok(trials)
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
