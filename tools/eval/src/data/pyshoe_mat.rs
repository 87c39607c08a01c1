//! One processed pyshoe Vicon trial (`data/vicon/processed/<trial>.mat`, written by the pyshoe
//! authors) turned into the layout [`crate::datasets::pyshoe`] reads: `<trial>.csv` and the
//! peer's figures in `<trial>.json`.
//!
//! The MAT-file's variables (pyshoe's `data/vicon/readme.txt`):
//! - `imu`, N x 6: specific force x, y, z (m/s²), then angular rate x, y, z (rad/s);
//! - `ts`, 1 x N: time of each IMU sample, s;
//! - `gt`, N x 3: the Vicon foot position at each IMU sample, m;
//! - `trial_error`, 1 x 5: the authors' 2-D RMSE, m, of their zero-velocity EKF with each stance
//!   detector, its threshold tuned for this trial, in the order of pyshoe's
//!   `process_error_vicon.py`: SHOE, ARED, AMVD, MBGTD, VICON;
//! - `best_detector`: the name of the detector with the lowest of these. It is a character
//!   matrix, which the MAT-file reader skips; the JSON's `best_detector` is the first detector
//!   with the lowest `trial_error`, which is the file's own answer in each of the 12 trials fetched.

use std::fmt::Write as _;

use matfile::MatFile;
use thiserror::Error;

use super::mat::{Matrix, NotReal, real_matrix};

/// The stance detectors in the order of `trial_error`.
pub const DETECTORS: [&str; 5] = ["shoe", "ared", "amvd", "mbgtd", "vicon"];

/// The header line of a converted trial.
pub const CSV_HEADER: &str =
    "t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyr_x_radps,gyr_y_radps,gyr_z_radps,gt_x_m,gt_y_m,gt_z_m";

/// What a converted trial's JSON says of the recording, beside the peer's figures.
const SOURCE: &str = "pyshoe VICON dataset (Wagstaff, Peretroukhin, Kelly), via mtahakoroglu/gait-driven-inertial-navigation-dataset";
const IMU: &str = "MicroStrain 3DM-GX5-25 foot-mounted, 200 Hz";
const TRUTH: &str = "Vicon foot position, metres, one row per IMU sample";

/// Why a MAT-file is not a processed pyshoe Vicon trial.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum TrialError {
    /// A variable the conversion needs is absent or not of the expected kind.
    #[error("variable {name}: {reason}")]
    Variable {
        /// The variable.
        name: &'static str,
        /// What is wrong.
        reason: String,
    },
}

/// The two files of a converted trial.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialFiles {
    /// `<trial>.csv`: [`CSV_HEADER`] and one row per IMU sample.
    pub csv: String,
    /// `<trial>.json`: the recording's description and the peer's figures.
    pub json: String,
    /// IMU samples (rows of the CSV).
    pub samples: usize,
}

/// The variable `name`, which must be a real numeric matrix.
fn numeric(file: &MatFile, name: &'static str) -> Result<Matrix, TrialError> {
    real_matrix(file, name).map_err(|e| TrialError::Variable {
        name,
        reason: match e {
            NotReal::Absent => "absent, or not a numeric matrix".into(),
            NotReal::Complex => "complex, expected real numbers".into(),
            NotReal::Inconsistent => "its values do not fill its dimensions".into(),
        },
    })
}

fn shape_error(name: &'static str, var: &Matrix, wanted: String) -> TrialError {
    TrialError::Variable {
        name,
        reason: format!("dimensions {:?}, expected {wanted}", var.dims),
    }
}

/// `x` as C's `%.9g` writes it (nine significant digits, trailing zeros dropped, exponent form
/// below 1e-4 and from 1e9): the published trial files carry the MAT-file's values so.
pub fn format_g9(x: f64) -> String {
    const DIGITS: i32 = 9;
    if !x.is_finite() {
        return if x.is_nan() {
            "nan".into()
        } else if x > 0.0 {
            "inf".into()
        } else {
            "-inf".into()
        };
    }
    if x == 0.0 {
        return if x.is_sign_negative() { "-0" } else { "0" }.into();
    }
    let sci = format!("{:.*e}", (DIGITS - 1) as usize, x);
    let (mantissa, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    let exp: i32 = exp.parse().unwrap_or(0);
    fn trim(s: &str) -> &str {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            s
        }
    }
    if !(-4..DIGITS).contains(&exp) {
        let sign = if exp < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa), exp.abs())
    } else {
        let fixed = format!("{:.*}", (DIGITS - 1 - exp) as usize, x);
        trim(&fixed).to_string()
    }
}

/// A JSON string literal.
fn quoted(s: &str) -> String {
    serde_json::Value::String(s.to_string()).to_string()
}

/// The first detector with the lowest finite figure; `None` when no figure is finite.
fn best_detector(errors: &[f64]) -> Option<&'static str> {
    let mut best: Option<(&'static str, f64)> = None;
    for (&name, &e) in DETECTORS.iter().zip(errors) {
        if e.is_finite() && best.is_none_or(|(_, b)| e < b) {
            best = Some((name, e));
        }
    }
    best.map(|(name, _)| name)
}

/// Converts the variables of one trial's MAT-file.
pub fn convert_trial(file: &MatFile) -> Result<TrialFiles, TrialError> {
    let imu = numeric(file, "imu")?;
    let n = imu.rows();
    if imu.cols() != 6 || n == 0 {
        return Err(shape_error("imu", &imu, "N x 6".into()));
    }
    let ts = numeric(file, "ts")?;
    if ts.len() != n || ts.dims.iter().filter(|&&d| d != 1).count() > 1 {
        return Err(shape_error("ts", &ts, format!("1 x {n} (one per imu row)")));
    }
    let gt = numeric(file, "gt")?;
    if gt.rows() != n || gt.cols() != 3 {
        return Err(shape_error("gt", &gt, format!("{n} x 3 (one per imu row)")));
    }
    let errors = numeric(file, "trial_error")?;
    if errors.len() != DETECTORS.len() {
        return Err(shape_error("trial_error", &errors, "1 x 5".into()));
    }
    let err = &errors.values;
    let best = best_detector(err);

    let mut csv = String::with_capacity(n * 120);
    csv.push_str(CSV_HEADER);
    for (row, t) in ts.values.iter().enumerate() {
        csv.push('\n');
        csv.push_str(&format_g9(*t));
        let values = (0..6)
            .map(|c| imu.at(row, c))
            .chain((0..3).map(|c| gt.at(row, c)));
        for v in values {
            csv.push(',');
            csv.push_str(&format_g9(v.unwrap_or(f64::NAN)));
        }
    }
    csv.push('\n');

    let mut json = String::new();
    let _ = write!(
        json,
        "{{\n \"source\": {},\n \"imu\": {},\n \"truth\": {},\n \"peer_2d_rmse_m_per_detector_tuned_per_trial\": {{",
        quoted(SOURCE),
        quoted(IMU),
        quoted(TRUTH)
    );
    for (k, (name, e)) in DETECTORS.iter().zip(err).enumerate() {
        let sep = if k + 1 < DETECTORS.len() { "," } else { "" };
        let value = serde_json::Number::from_f64(*e).map_or("null".to_string(), |v| v.to_string());
        let _ = write!(json, "\n  {}: {value}{sep}", quoted(name));
    }
    json.push_str("\n }");
    if let Some(best) = best {
        let _ = write!(json, ",\n \"best_detector\": {}", quoted(best));
    }
    json.push_str("\n}\n");
    Ok(TrialFiles {
        csv,
        json,
        samples: n,
    })
}

#[cfg(test)]
mod tests {
    use super::super::mat::{fixture, parse_mat};
    use super::*;

    const ERRORS: [f64; 5] = [0.032, 0.04, 0.032, 0.036, 0.443];

    /// A two-sample trial's variables; `gt` and `trial_error` as given.
    fn variables(gt: Option<&[&[f64]]>, errors: &[f64]) -> Vec<Vec<u8>> {
        let mut vars = vec![
            fixture::doubles(
                "imu",
                &[
                    &[
                        -2.78189194097,
                        0.3,
                        -9.35,
                        0.00396896712,
                        0.0,
                        -3.70643102e-6,
                    ],
                    &[-2.8412451704299997, 0.31, -9.33, 0.0036, -0.0011, 0.0016],
                ],
            ),
            fixture::doubles("ts", &[&[0.0051913, 0.010160356]]),
            fixture::doubles("trial_error", &[errors]),
            fixture::chars("best_detector", "shoe"),
        ];
        if let Some(gt) = gt {
            vars.push(fixture::doubles("gt", gt));
        }
        vars
    }

    const GT: &[&[f64]] = &[
        &[-0.027581451797599996, 0.0634, 0.126],
        &[-0.0276005388154, 0.0634, 0.126],
    ];

    fn convert(vars: &[Vec<u8>]) -> Result<TrialFiles, TrialError> {
        convert_trial(&parse_mat(&fixture::file(vars)).unwrap())
    }

    #[test]
    fn nine_significant_digits_as_printf_g() {
        assert_eq!(format_g9(-2.78189194097), "-2.78189194");
        assert_eq!(format_g9(0.010160356), "0.010160356");
        assert_eq!(format_g9(-0.027581451797599996), "-0.0275814518");
        assert_eq!(format_g9(-3.70643102e-6), "-3.70643102e-06");
        assert_eq!(format_g9(1e-5), "1e-05");
        assert_eq!(format_g9(123456789012.0), "1.23456789e+11");
        assert_eq!(format_g9(100.0), "100");
        assert_eq!(format_g9(1.0), "1");
        assert_eq!(format_g9(0.0), "0");
        assert_eq!(format_g9(-0.0), "-0");
        assert_eq!(format_g9(0.0001), "0.0001");
        assert_eq!(format_g9(999999999.6), "1e+09");
    }

    #[test]
    fn a_trial_becomes_csv_rows_and_the_authors_figures() {
        let files = convert(&variables(Some(GT), &ERRORS)).unwrap();
        assert_eq!(files.samples, 2);
        let lines: Vec<&str> = files.csv.lines().collect();
        assert_eq!(lines[0], CSV_HEADER);
        assert_eq!(
            lines[1],
            "0.0051913,-2.78189194,0.3,-9.35,0.00396896712,0,-3.70643102e-06,-0.0275814518,0.0634,0.126"
        );
        assert_eq!(lines.len(), 3);
        let json: serde_json::Value = serde_json::from_str(&files.json).unwrap();
        let peer = &json["peer_2d_rmse_m_per_detector_tuned_per_trial"];
        assert_eq!(peer["shoe"], 0.032);
        assert_eq!(peer["ared"], 0.04);
        assert_eq!(peer["vicon"], 0.443);
        // shoe and amvd share the lowest figure: the first in trial_error's order is named.
        assert_eq!(json["best_detector"], "shoe");
        // The evaluation's own loader reads what is written.
        let path = std::path::Path::new("t.json");
        let read = crate::datasets::pyshoe::parse_peer(path, &files.json).unwrap();
        assert!(read.is_some());

        // Saved compressed, the same trial converts to the same files.
        let compressed: Vec<Vec<u8>> = variables(Some(GT), &ERRORS)
            .iter()
            .map(|v| fixture::compressed(v))
            .collect();
        assert_eq!(convert(&compressed), Ok(files));
    }

    #[test]
    fn the_best_detector_is_the_lowest_finite_figure() {
        assert_eq!(
            best_detector(&[0.05, 0.04, 0.04, 0.06, 0.033]),
            Some("vicon")
        );
        assert_eq!(
            best_detector(&[f64::NAN, 0.04, 0.03, 0.06, 0.5]),
            Some("amvd")
        );
        assert_eq!(best_detector(&[f64::NAN; 5]), None);
        // Without a finite figure the JSON carries the figures alone.
        let files = convert(&variables(Some(GT), &[f64::NAN; 5])).unwrap();
        assert!(!files.json.contains("best_detector"), "{}", files.json);
        assert!(files.json.contains("\"shoe\": null"), "{}", files.json);
    }

    #[test]
    fn a_missing_or_misshapen_variable_is_named() {
        assert_eq!(
            convert(&variables(None, &ERRORS)),
            Err(TrialError::Variable {
                name: "gt",
                reason: "absent, or not a numeric matrix".into()
            })
        );
        let e = convert(&variables(Some(&[&[0.0; 3]]), &ERRORS)).unwrap_err();
        assert_eq!(
            e.to_string(),
            "variable gt: dimensions [1, 3], expected 2 x 3 (one per imu row)"
        );
        let e = convert(&variables(Some(GT), &ERRORS[..4])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "variable trial_error: dimensions [1, 4], expected 1 x 5"
        );
        let mut complex = variables(None, &ERRORS);
        complex.push(fixture::complex_doubles("gt", GT));
        assert_eq!(
            convert(&complex).unwrap_err().to_string(),
            "variable gt: complex, expected real numbers"
        );
    }
}
