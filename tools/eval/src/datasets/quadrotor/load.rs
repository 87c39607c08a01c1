//! Loading one trial: its IMU files repaired ([`repair`]) and aligned on the reference unit's
//! rows ([`align`], [`subrow`]), its truth moved onto that time base ([`clock`]).
//!
//! A unit file that cannot be used (unreadable, malformed header or line, too short, not
//! overlapping the others) is skipped with a note and counted, so that one failed unit does not
//! cost the flight; the trial fails only when no unit is left.

use std::path::Path;

use crate::datasets::csv::{read_numeric, read_numeric_allowing_gaps};
use crate::datasets::error::DatasetError;

use super::repair::{Repairs, Row, repair};
use super::{
    IMU_HEADER, IMU_RATE_HZ, ImuSample, ImuSeries, MAX_IMUS, MIN_IMU_ROWS, MIN_TRUTH_ROWS,
    TRUTH_HEADER, Trial, TruthRow, align, clock, frame, subrow, trial_name,
};

/// One IMU file as read and repaired: times, and samples converted to SI/FRD.
struct RawImu {
    imu: usize,
    times: Vec<f64>,
    samples: Vec<ImuSample>,
    repairs: Repairs,
}

fn read_imu(path: &Path, imu: usize) -> Result<RawImu, DatasetError> {
    let rows: Vec<Row> = read_numeric_allowing_gaps(path, &IMU_HEADER)?;
    let (rows, repairs) = repair(&rows, 1.0 / IMU_RATE_HZ);
    if rows.len() < MIN_IMU_ROWS {
        return Err(DatasetError::TooShort {
            path: path.to_path_buf(),
            rows: rows.len(),
            min: MIN_IMU_ROWS,
        });
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
        repairs,
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

/// Every unit file of the trial that can be used, the notes and counts of those that cannot,
/// and the first error (returned when no unit is left).
fn read_units(
    path: &Path,
    notes: &mut Vec<String>,
    skipped: &mut usize,
) -> (Vec<RawImu>, Option<DatasetError>) {
    let mut raw = Vec::new();
    let mut first_error = None;
    for imu in 1..=MAX_IMUS {
        let file = path.join(format!("IMU_{imu}.csv"));
        if !file.is_file() {
            notes.push(format!("IMU_{imu}.csv missing: skipped"));
            continue;
        }
        match read_imu(&file, imu) {
            Ok(series) => {
                if !series.repairs.is_clean() {
                    notes.push(format!(
                        "IMU_{imu}.csv repaired: {}",
                        series.repairs.phrases().join(", ")
                    ));
                }
                raw.push(series);
            }
            Err(e) => {
                notes.push(format!("IMU_{imu}.csv skipped: {e}"));
                *skipped += 1;
                first_error.get_or_insert(e);
            }
        }
    }
    (raw, first_error)
}

/// Loads one trial directory: every usable `IMU_k.csv` present (k = 1..=4), repaired and
/// aligned on the first one's time base, and `GT.csv` moved onto it. Missing or unusable IMU
/// files are noted and counted, not fatal, while one unit is left.
pub fn load_trial(path: &Path) -> Result<Trial, DatasetError> {
    let name = trial_name(path);
    let mut notes = Vec::new();
    let mut skipped = 0;
    let (mut raw, first_error) = read_units(path, &mut notes, &mut skipped);
    if raw.is_empty() {
        return Err(first_error.unwrap_or_else(|| DatasetError::MissingFile {
            path: path.join("IMU_1.csv"),
            what: "no IMU_1..4.csv in the trial",
        }));
    }
    let truth_path = path.join("GT.csv");
    if !truth_path.is_file() {
        return Err(DatasetError::MissingFile {
            path: truth_path,
            what: "ground truth",
        });
    }
    let mut truth = read_truth(&truth_path)?;

    // Lag of each IMU against the reference, on the rate magnitude (mounting-independent); a
    // unit that overlaps nowhere is skipped.
    let reference_rate = rate_magnitude(&raw[0].samples);
    let (reference_imu, reference_len) = (raw[0].imu, raw[0].samples.len());
    let mut lags: Vec<i64> = vec![0];
    let mut k = 1;
    while k < raw.len() {
        let rate = rate_magnitude(&raw[k].samples);
        match align::estimate_lag(&reference_rate, &rate, align::MAX_LAG_ROWS) {
            Some(lag) => {
                lags.push(lag);
                k += 1;
            }
            None => {
                let series = raw.remove(k);
                notes.push(format!(
                    "IMU_{}.csv skipped: {} rows do not overlap IMU_{reference_imu} ({reference_len} rows)",
                    series.imu,
                    series.samples.len(),
                ));
                skipped += 1;
            }
        }
    }
    let reference = &raw[0];
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
    let mut imus: Vec<ImuSeries> = raw
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
            ImuSeries {
                imu: series.imu,
                lag_rows: lag,
                residual_lag_rows: [0.0; 2],
                repairs: series.repairs,
                truth_offset_s: 0.0,
                samples,
            }
        })
        .collect();
    let reference_rate = rate_magnitude(&imus[0].samples);
    let mut mean_residual = vec![0.0; imus.len()];
    for (series, mean) in imus.iter_mut().zip(&mut mean_residual).skip(1) {
        let lag = subrow::residual_lag(&reference_rate, &rate_magnitude(&series.samples));
        let lo = lag.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = lag.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        *mean = lag.iter().sum::<f64>() / lag.len().max(1) as f64;
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

    // Truth clock against the reference unit's gyro.
    let gyro: Vec<[f64; 3]> = imus[0].samples.iter().map(|s| s.gyro_rps).collect();
    let truth_offset_s = clock::estimate_truth_offset(
        &clock::truth_body_rates(&truth),
        &gyro,
        times[0],
        1.0 / IMU_RATE_HZ,
        clock::MAX_TRUTH_OFFSET_S,
        clock::GRID_S,
    )
    .unwrap_or_else(|| {
        notes.push("truth clock offset not estimable: kept at 0".into());
        0.0
    });
    truth.iter_mut().for_each(|r| r.t_s += truth_offset_s);
    // Unit k's file row j + lag holds the instant of reference row j, so its own clock is
    // further on by its whole-row and (mean) residual lag.
    for (series, mean) in imus.iter_mut().zip(&mean_residual) {
        series.truth_offset_s = truth_offset_s + (series.lag_rows as f64 + mean) / IMU_RATE_HZ;
    }

    let mut repairs = imus.iter().fold(Repairs::default(), |a, s| a + s.repairs);
    repairs.imu_files_skipped = skipped;
    Ok(Trial {
        name,
        path: path.to_path_buf(),
        imus,
        truth,
        truth_offset_s,
        repairs,
        notes,
    })
}
