//! The pyshoe Vicon data set (Wagstaff, Peretroukhin, Kelly): a foot-mounted MicroStrain
//! 3DM-GX5-25 at 200 Hz, with the Vicon foot position on every row.
//!
//! One `<trial>.csv` per trial, header [`HEADER`]: time s, specific force m/s², rate rad/s, Vicon
//! position m. The unit's axes are z down in all trials but one (at rest `acc_z ≈ −g`), and those
//! rows are taken as they are; `2018-02-22-10-10-56` was recorded with the unit the other way up
//! (`acc_z ≈ +g` at rest), so a trial whose specific force points along +z on average is turned
//! 180° about x and marked [`FootTrial::turned_over`].
//!
//! Beside each CSV, `<trial>.json` holds the peer's 2-D RMSE per stance detector (each detector's
//! threshold tuned for the trial) and the name of the best one.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::DatasetError;
use super::csv::parse_numeric;
use super::foot::{
    FootSample, FootTrial, PeerResult, assemble, data_lines, read_text, turn_about_x,
};

/// The header of a trial file.
pub const HEADER: [&str; 10] = [
    "t_s",
    "acc_x_mps2",
    "acc_y_mps2",
    "acc_z_mps2",
    "gyr_x_radps",
    "gyr_y_radps",
    "gyr_z_radps",
    "gt_x_m",
    "gt_y_m",
    "gt_z_m",
];

/// The parts of the JSON beside a trial that are read; other keys are ignored.
#[derive(Debug, Deserialize)]
struct PeerFile {
    /// 2-D RMSE, m, per stance detector.
    peer_2d_rmse_m_per_detector_tuned_per_trial: Option<BTreeMap<String, f64>>,
    /// The detector with the best figure.
    best_detector: Option<String>,
}

/// The `*.csv` files directly in `dir`, sorted by name.
pub fn list_trials(dir: &Path) -> Result<Vec<PathBuf>, DatasetError> {
    let entries = std::fs::read_dir(dir).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => DatasetError::MissingFile {
            path: dir.to_path_buf(),
            what: "pyshoe data directory; `rins data fetch pyshoe-vicon` downloads it",
        },
        _ => DatasetError::Io {
            path: dir.to_path_buf(),
            source,
        },
    })?;
    let mut files = Vec::new();
    for entry in entries {
        let path = entry
            .map_err(|source| DatasetError::Io {
                path: dir.to_path_buf(),
                source,
            })?
            .path();
        if path.is_file() && path.extension().is_some_and(|x| x == "csv") {
            files.push(path);
        }
    }
    files.sort();
    Ok(files)
}

/// Loads one trial CSV, and the peer's figure from the JSON beside it when there is one.
pub fn load_trial(path: &Path) -> Result<FootTrial, DatasetError> {
    let text = read_text(path, "pyshoe trial")?;
    let json_path = path.with_extension("json");
    let peer = match std::fs::read_to_string(&json_path) {
        Ok(json) => parse_peer(&json_path, &json)?,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
        Err(source) => {
            return Err(DatasetError::Io {
                path: json_path,
                source,
            });
        }
    };
    parse_trial(path, &text, peer)
}

/// [`load_trial`] on the CSV text already read; `path` names the trial and the errors.
pub(crate) fn parse_trial(
    path: &Path,
    text: &str,
    peer: Option<PeerResult>,
) -> Result<FootTrial, DatasetError> {
    let rows = parse_numeric(path, text, &HEADER)?;
    // Gravity dominates the mean specific force of a walk: its sign on z tells which way up the
    // unit was, whether or not the recording starts at rest.
    let turned_over = rows.iter().map(|r| r[3]).sum::<f64>() > 0.0;
    let axes = |v: [f64; 3]| if turned_over { turn_about_x(v) } else { v };
    let samples: Vec<FootSample> = rows
        .iter()
        .map(|r| FootSample {
            t_s: r[0],
            accel_mps2: axes([r[1], r[2], r[3]]),
            gyro_rps: axes([r[4], r[5], r[6]]),
        })
        .collect();
    let truth = rows.iter().map(|r| [r[7], r[8], r[9]]).collect();
    let trial = assemble(path, samples, &data_lines(text), Some(truth), peer)?;
    Ok(FootTrial {
        turned_over,
        ..trial
    })
}

/// The 1-based line of the first line of `text` containing `needle`; 1 when none does.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines()
        .position(|l| l.contains(needle))
        .map_or(1, |i| i + 1)
}

/// The peer's figures, m, from the JSON text of a trial: the best one (that of `best_detector`,
/// or the smallest when that key is absent) and the SHOE detector's. `None` when the file gives
/// no figures.
pub(crate) fn parse_peer(path: &Path, text: &str) -> Result<Option<PeerResult>, DatasetError> {
    let file: PeerFile = serde_json::from_str(text).map_err(|e| {
        let message = e.to_string();
        let position = format!(" at line {} column {}", e.line(), e.column());
        DatasetError::Malformed {
            path: path.to_path_buf(),
            line: e.line().max(1),
            reason: format!(
                "{} (column {})",
                message.strip_suffix(&position).unwrap_or(&message),
                e.column()
            ),
        }
    })?;
    let Some(per_detector) = file.peer_2d_rmse_m_per_detector_tuned_per_trial else {
        return Ok(None);
    };
    let malformed = |needle: &str, reason: String| DatasetError::Malformed {
        path: path.to_path_buf(),
        line: line_of(text, needle),
        reason,
    };
    if let Some((name, rmse)) = per_detector
        .iter()
        .find(|(_, r)| !r.is_finite() || **r < 0.0)
    {
        return Err(malformed(
            &format!("\"{name}\""),
            format!("RMSE of {name} = {rmse}: not a distance"),
        ));
    }
    let best = match file.best_detector {
        Some(best) => Some(per_detector.get(&best).copied().ok_or_else(|| {
            malformed(
                "\"best_detector\"",
                format!("best_detector {best:?} has no RMSE"),
            )
        })?),
        None => per_detector.values().copied().reduce(f64::min),
    };
    Ok(best.map(|best_m| PeerResult::Armse2d {
        best_m,
        shoe_m: per_detector.get("shoe").copied(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A trial of `seconds` at 200 Hz, still, z down, the foot at (1, 2, 0.1).
    fn trial_text(seconds: f64) -> String {
        let values = "-0.1,0.2,-9.8,0.001,0,-0.002,1,2,0.1";
        crate::datasets::csv::still_rows(&HEADER, 200.0, seconds, 1, values)
    }

    #[test]
    fn rows_are_taken_as_recorded_with_truth_per_sample() {
        let text = trial_text(2.5);
        let trial = parse_trial(
            Path::new("d/2017-11-22-11-22-03.csv"),
            &text,
            Some(PeerResult::Armse2d {
                best_m: 0.03,
                shoe_m: None,
            }),
        )
        .unwrap();
        assert_eq!(trial.name, "2017-11-22-11-22-03");
        assert_eq!(trial.samples.len(), 501);
        assert_eq!(trial.samples[0].accel_mps2, [-0.1, 0.2, -9.8]);
        assert_eq!(trial.samples[0].gyro_rps, [0.001, 0.0, -0.002]);
        let truth = trial.truth_m.as_ref().unwrap();
        assert_eq!(truth.len(), trial.samples.len());
        assert_eq!(truth[0], [1.0, 2.0, 0.1]);
        assert_eq!(
            trial.peer,
            Some(PeerResult::Armse2d {
                best_m: 0.03,
                shoe_m: None
            })
        );
        assert_eq!(trial.dropped_duplicates, 0);
        assert!((trial.rate_hz - 200.0).abs() < 1e-6, "{}", trial.rate_hz);
    }

    #[test]
    fn a_trial_recorded_z_up_is_turned_over() {
        let text =
            trial_text(2.0).replace(",0.2,-9.8,0.001,0,-0.002,", ",0.2,9.8,0.001,0.003,-0.002,");
        let trial = parse_trial(Path::new("d/t.csv"), &text, None).unwrap();
        assert!(trial.turned_over);
        assert_eq!(trial.samples[0].accel_mps2, [-0.1, -0.2, -9.8]);
        assert_eq!(trial.samples[0].gyro_rps, [0.001, -0.003, 0.002]);
        assert_eq!(trial.truth_m.unwrap()[0], [1.0, 2.0, 0.1]);
        let upright = parse_trial(Path::new("d/t.csv"), &trial_text(2.0), None).unwrap();
        assert!(!upright.turned_over);
    }

    #[test]
    fn a_wrong_header_names_the_file() {
        let text = trial_text(3.0).replacen("gyr_z_radps", "gyr_z_dps", 1);
        let e = parse_trial(Path::new("d/t1.csv"), &text, None).unwrap_err();
        assert!(matches!(e, DatasetError::Header { .. }), "{e}");
        assert!(e.to_string().starts_with("d/t1.csv:1: header"), "{e}");
    }

    #[test]
    fn short_and_backwards_trials_are_refused() {
        let e = parse_trial(Path::new("d/t.csv"), &trial_text(1.0), None).unwrap_err();
        assert!(matches!(e, DatasetError::TooShort { rows: 201, .. }), "{e}");
        let text = trial_text(3.0) + "1.0,0,0,-9.8,0,0,0,0,0,0\n";
        let e = parse_trial(Path::new("d/t.csv"), &text, None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "d/t.csv:603: time 1 s goes back from 3.005 s"
        );
    }

    #[test]
    fn peer_figure_is_the_best_detectors_or_the_smallest() {
        let p = Path::new("d/t.json");
        let json = r#"{
 "imu": "MicroStrain 3DM-GX5-25 foot-mounted, 200 Hz",
 "peer_2d_rmse_m_per_detector_tuned_per_trial": {
  "shoe": 0.042,
  "ared": 0.04,
  "vicon": 0.045
 },
 "best_detector": "ared"
}"#;
        let figures = |best_m| {
            Some(PeerResult::Armse2d {
                best_m,
                shoe_m: Some(0.042),
            })
        };
        assert_eq!(parse_peer(p, json).unwrap(), figures(0.04));
        let without_best = json.replace(",\n \"best_detector\": \"ared\"", "");
        assert_eq!(parse_peer(p, &without_best).unwrap(), figures(0.04));
        let shoe = json.replace("\"ared\"\n", "\"shoe\"\n");
        assert_eq!(parse_peer(p, &shoe).unwrap(), figures(0.042));
        assert_eq!(parse_peer(p, r#"{"imu": "x"}"#).unwrap(), None);
        assert_eq!(
            parse_peer(p, r#"{"peer_2d_rmse_m_per_detector_tuned_per_trial": {}}"#).unwrap(),
            None
        );

        let unknown = json.replace("\"ared\"\n", "\"mbgtd\"\n");
        let e = parse_peer(p, &unknown).unwrap_err();
        assert_eq!(
            e.to_string(),
            "d/t.json:8: best_detector \"mbgtd\" has no RMSE"
        );
        let negative = json.replace("0.045", "-1");
        let e = parse_peer(p, &negative).unwrap_err();
        assert_eq!(
            e.to_string(),
            "d/t.json:6: RMSE of vicon = -1: not a distance"
        );
        let text = json.replace("0.042", "\"x\"");
        let e = parse_peer(p, &text).unwrap_err();
        assert!(e.to_string().starts_with("d/t.json:4: invalid type"), "{e}");
    }

    #[test]
    fn files_list_and_load_with_and_without_peer_json() {
        let dir = std::env::temp_dir().join(format!("rins-pyshoe-test-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let text = trial_text(2.0);
        std::fs::write(dir.join("b.csv"), &text).unwrap();
        std::fs::write(dir.join("a.csv"), &text).unwrap();
        std::fs::write(
            dir.join("a.json"),
            r#"{"peer_2d_rmse_m_per_detector_tuned_per_trial": {"shoe": 0.032, "ared": 0.031}}"#,
        )
        .unwrap();
        std::fs::write(dir.join("notes.txt"), "not a trial").unwrap();
        std::fs::create_dir_all(dir.join("sub.csv")).unwrap();

        let listed = list_trials(&dir);
        let a = load_trial(&dir.join("a.csv"));
        let b = load_trial(&dir.join("b.csv"));
        let missing = load_trial(&dir.join("c.csv"));
        let _ = std::fs::remove_dir_all(&dir);

        assert_eq!(listed.unwrap(), vec![dir.join("a.csv"), dir.join("b.csv")]);
        assert_eq!(
            a.unwrap().peer,
            Some(PeerResult::Armse2d {
                best_m: 0.031,
                shoe_m: Some(0.032)
            })
        );
        assert_eq!(b.unwrap().peer, None);
        assert!(
            matches!(missing, Err(DatasetError::MissingFile { .. })),
            "{missing:?}"
        );
        let gone = list_trials(&dir).unwrap_err();
        assert!(matches!(gone, DatasetError::MissingFile { .. }), "{gone}");
    }
}
