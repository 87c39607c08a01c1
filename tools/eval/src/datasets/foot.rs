//! A foot-mounted IMU recording, whatever its source: samples in the product's body convention
//! (FRD-like, z down: at rest the specific force is `[0, 0, −g]`), SI units, times strictly
//! increasing.
//!
//! The loaders ([`super::pyshoe`], [`super::xio`]) convert their rows into [`FootSample`]s and
//! hand them to `assemble`, which drops rows repeating the previous time (counting them),
//! refuses time going backwards and recordings shorter than [`MIN_DURATION_S`], and measures the
//! sample rate.

use std::path::{Path, PathBuf};

use super::DatasetError;

/// Shortest recording accepted, s: the navigator needs the foot still for its alignment and then
/// some walking for a figure to mean anything.
pub const MIN_DURATION_S: f64 = 2.0;

/// One IMU sample, body frame z down.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootSample {
    /// Time on the recording's clock, s.
    pub t_s: f64,
    /// Body rate, rad/s.
    pub gyro_rps: [f64; 3],
    /// Specific force, m/s².
    pub accel_mps2: [f64; 3],
}

/// What others obtained on the same recording, to compare against.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PeerResult {
    /// The peer's averaged 2-D error against the reference trajectory ("ARMSE", see
    /// `foot::metrics::peer_armse_2d`), its threshold tuned per trial, m: of its best detector
    /// on the trial, and of its SHOE detector when given.
    Armse2d {
        /// The best detector's figure.
        best_m: f64,
        /// The SHOE detector's figure.
        shoe_m: Option<f64>,
    },
    /// Distance between the start and end positions of a closed loop, m.
    EndErrorM(f64),
}

/// One recorded walk.
#[derive(Debug, Clone, PartialEq)]
pub struct FootTrial {
    /// File stem, e.g. `short_walk` or `2017-11-22-11-22-03`.
    pub name: String,
    /// The file the samples came from.
    pub path: PathBuf,
    /// The samples, times strictly increasing.
    pub samples: Vec<FootSample>,
    /// Reference foot position per sample (same length as `samples`), m, in the reference
    /// system's own frame (x, y horizontal, z up for Vicon), when the recording has one.
    pub truth_m: Option<Vec<[f64; 3]>>,
    /// The published or peer result on this recording, when known.
    pub peer: Option<PeerResult>,
    /// Rows dropped because their time equalled the previous kept row's.
    pub dropped_duplicates: usize,
    /// The recorded z axis pointed up, against its data set's convention (the unit was mounted
    /// the other way up): both vectors were turned 180° about x, see [`turn_about_x`].
    pub turned_over: bool,
    /// Median sample rate (1 / median time step), Hz.
    pub rate_hz: f64,
}

impl FootTrial {
    /// Time from the first to the last sample, s.
    pub fn duration_s(&self) -> f64 {
        match (self.samples.first(), self.samples.last()) {
            (Some(a), Some(b)) => b.t_s - a.t_s,
            _ => 0.0,
        }
    }
}

/// A vector turned 180° about x: `(x, y, z) → (x, −y, −z)`. A proper rotation, so it takes a
/// z-up body frame to a z-down one without mirroring it, for rates and specific force alike.
pub fn turn_about_x(v: [f64; 3]) -> [f64; 3] {
    [v[0], -v[1], -v[2]]
}

/// 1 / the median of the steps between consecutive `times`, Hz. `None` with fewer than two times
/// or when that median step is not a positive finite number.
pub fn median_rate_hz(times: &[f64]) -> Option<f64> {
    let mut steps: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    if steps.is_empty() {
        return None;
    }
    steps.sort_by(f64::total_cmp);
    let mid = steps.len() / 2;
    let median = if steps.len().is_multiple_of(2) {
        0.5 * (steps[mid - 1] + steps[mid])
    } else {
        steps[mid]
    };
    (median.is_finite() && median > 0.0).then(|| 1.0 / median)
}

/// The file stem of `path` as a trial name.
pub(crate) fn stem(path: &Path) -> String {
    path.file_stem()
        .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
}

/// Reads a whole file; a file that is not there is [`DatasetError::MissingFile`].
pub(crate) fn read_text(path: &Path, what: &'static str) -> Result<String, DatasetError> {
    std::fs::read_to_string(path).map_err(|source| match source.kind() {
        std::io::ErrorKind::NotFound => DatasetError::MissingFile {
            path: path.to_path_buf(),
            what,
        },
        _ => DatasetError::Io {
            path: path.to_path_buf(),
            source,
        },
    })
}

/// The 1-based file line of each data row of `text`, as the CSV reader counts them: after the
/// header, skipping blank lines.
pub(crate) fn data_lines(text: &str) -> Vec<usize> {
    text.lines()
        .enumerate()
        .skip(1)
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(i, _)| i + 1)
        .collect()
}

/// Builds a trial from samples in file order. `lines[i]` is the file line of `samples[i]` (for
/// errors); `truth_m`, when given, has one entry per sample and is thinned with them.
///
/// A sample whose time equals the last kept one is dropped and counted; one whose time is
/// earlier is [`DatasetError::Malformed`] at its line. Fewer than [`MIN_DURATION_S`] of kept
/// samples is [`DatasetError::TooShort`], with the rows that span takes at the file's rate.
pub(crate) fn assemble(
    path: &Path,
    samples: Vec<FootSample>,
    lines: &[usize],
    truth_m: Option<Vec<[f64; 3]>>,
    peer: Option<PeerResult>,
) -> Result<FootTrial, DatasetError> {
    let mut kept: Vec<FootSample> = Vec::with_capacity(samples.len());
    let mut kept_truth = truth_m.as_ref().map(|t| Vec::with_capacity(t.len()));
    let mut dropped = 0;
    for (i, s) in samples.into_iter().enumerate() {
        if let Some(prev) = kept.last() {
            if s.t_s == prev.t_s {
                dropped += 1;
                continue;
            }
            if s.t_s < prev.t_s {
                return Err(DatasetError::Malformed {
                    path: path.to_path_buf(),
                    line: lines.get(i).copied().unwrap_or(i + 2),
                    reason: format!("time {} s goes back from {} s", s.t_s, prev.t_s),
                });
            }
        }
        kept.push(s);
        if let (Some(out), Some(truth)) = (kept_truth.as_mut(), truth_m.as_ref()) {
            out.extend(truth.get(i).copied());
        }
    }
    let times: Vec<f64> = kept.iter().map(|s| s.t_s).collect();
    let rate = median_rate_hz(&times);
    let span = match (times.first(), times.last()) {
        (Some(a), Some(b)) => b - a,
        _ => 0.0,
    };
    let rate_hz = match rate {
        Some(rate) if span >= MIN_DURATION_S => rate,
        _ => {
            let per_s = rate.unwrap_or(1.0);
            return Err(DatasetError::TooShort {
                path: path.to_path_buf(),
                rows: kept.len(),
                min: ((MIN_DURATION_S * per_s).ceil() as usize + 1).max(2),
            });
        }
    };
    Ok(FootTrial {
        name: stem(path),
        path: path.to_path_buf(),
        samples: kept,
        truth_m: kept_truth,
        peer,
        dropped_duplicates: dropped,
        turned_over: false,
        rate_hz,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(t_s: f64) -> FootSample {
        FootSample {
            t_s,
            gyro_rps: [0.0; 3],
            accel_mps2: [0.0, 0.0, -9.81],
        }
    }

    #[test]
    fn median_rate_ignores_a_few_odd_steps() {
        assert_eq!(median_rate_hz(&[]), None);
        assert_eq!(median_rate_hz(&[1.0]), None);
        assert_eq!(median_rate_hz(&[1.0, 1.0]), None);
        let mut times: Vec<f64> = (0..100).map(|k| k as f64 * 0.005).collect();
        times[50] += 0.002;
        times.push(10.0);
        let rate = median_rate_hz(&times).unwrap();
        assert!((rate - 200.0).abs() < 1e-6, "{rate}");
        // Even count of steps: the mean of the middle two.
        assert!((median_rate_hz(&[0.0, 0.1, 0.3]).unwrap() - 1.0 / 0.15).abs() < 1e-9);
    }

    #[test]
    fn data_lines_skip_the_header_and_blank_lines() {
        assert_eq!(data_lines("h\n1\n\n2\r\n \n3"), vec![2, 4, 6]);
    }

    #[test]
    fn repeated_times_are_dropped_with_their_truth_and_counted() {
        let times = [0.0, 0.5, 0.5, 1.0, 1.5, 1.5, 1.5, 2.0, 2.5];
        let samples: Vec<FootSample> = times.iter().map(|&t| at(t)).collect();
        let truth: Vec<[f64; 3]> = (0..times.len()).map(|k| [k as f64, 0.0, 0.0]).collect();
        let lines: Vec<usize> = (2..2 + times.len()).collect();
        let trial = assemble(Path::new("d/w.csv"), samples, &lines, Some(truth), None).unwrap();
        assert_eq!(trial.name, "w");
        assert_eq!(trial.dropped_duplicates, 3);
        let kept: Vec<f64> = trial.samples.iter().map(|s| s.t_s).collect();
        assert_eq!(kept, vec![0.0, 0.5, 1.0, 1.5, 2.0, 2.5]);
        let xs: Vec<f64> = trial.truth_m.unwrap().iter().map(|p| p[0]).collect();
        assert_eq!(xs, vec![0.0, 1.0, 3.0, 4.0, 7.0, 8.0]);
        assert!((trial.rate_hz - 2.0).abs() < 1e-12);
    }

    #[test]
    fn time_going_back_names_the_line() {
        let samples: Vec<FootSample> = [0.0, 1.0, 2.0, 1.5, 3.0].iter().map(|&t| at(t)).collect();
        let e = assemble(Path::new("d/w.csv"), samples, &[2, 3, 5, 6, 7], None, None).unwrap_err();
        assert_eq!(e.to_string(), "d/w.csv:6: time 1.5 s goes back from 2 s");
    }

    #[test]
    fn less_than_two_seconds_is_too_short() {
        let samples: Vec<FootSample> = (0..100).map(|k| at(k as f64 * 0.01)).collect();
        let lines: Vec<usize> = (2..102).collect();
        let e = assemble(Path::new("d/w.csv"), samples, &lines, None, None).unwrap_err();
        assert!(
            matches!(
                e,
                DatasetError::TooShort {
                    rows: 100,
                    min: 201,
                    ..
                }
            ),
            "{e}"
        );
        let e = assemble(Path::new("d/w.csv"), vec![at(0.0)], &[2], None, None).unwrap_err();
        assert!(matches!(e, DatasetError::TooShort { rows: 1, .. }), "{e}");
    }

    #[test]
    fn a_missing_file_is_named() {
        let e = read_text(Path::new("/nonexistent/rins/w.csv"), "walk").unwrap_err();
        assert!(matches!(e, DatasetError::MissingFile { .. }), "{e}");
        assert_eq!(e.to_string(), "/nonexistent/rins/w.csv: missing (walk)");
    }

    /// Every recording at hand, when the recordings directory is there.
    #[test]
    fn real_recordings_load_with_their_rates_and_a_z_down_rest() {
        let data = super::super::recordings_dir();
        if !data.is_dir() {
            return;
        }
        let check_rest = |trial: &FootTrial| {
            let a = trial.samples[0].accel_mps2;
            let norm = a.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!((norm - 9.81).abs() < 1.5, "{}: |f| = {norm}", trial.name);
            assert!(a[2] < -7.0, "{}: f = {a:?}", trial.name);
        };
        let pyshoe_dir = data.join("pyshoe-vicon");
        if pyshoe_dir.is_dir() {
            let files = super::super::pyshoe::list_trials(&pyshoe_dir).unwrap();
            assert!(!files.is_empty());
            for file in &files {
                let trial = super::super::pyshoe::load_trial(file).unwrap();
                assert!(
                    (180.0..=220.0).contains(&trial.rate_hz),
                    "{}: {}",
                    trial.name,
                    trial.rate_hz
                );
                assert_eq!(
                    trial.truth_m.as_ref().map(Vec::len),
                    Some(trial.samples.len())
                );
                assert!(
                    matches!(trial.peer, Some(PeerResult::Armse2d { best_m, .. }) if best_m > 0.0 && best_m < 1.0)
                );
                assert!(trial.duration_s() > 10.0);
                assert_eq!(
                    trial.turned_over,
                    trial.name == "2018-02-22-10-10-56",
                    "{}",
                    trial.name
                );
                check_rest(&trial);
            }
        }
        for (name, peer) in [("short_walk", 0.082), ("long_walk", 0.421)] {
            let file = data.join("xio-gait").join(format!("{name}.csv"));
            if !file.is_file() {
                continue;
            }
            let trial = super::super::xio::load_walk(&file).unwrap();
            assert!(
                (350.0..=450.0).contains(&trial.rate_hz),
                "{name}: {}",
                trial.rate_hz
            );
            assert_eq!(trial.peer, Some(PeerResult::EndErrorM(peer)));
            assert!(trial.dropped_duplicates > 0, "{name}");
            assert!(!trial.turned_over);
            assert!(trial.samples.windows(2).all(|w| w[1].t_s > w[0].t_s));
            check_rest(&trial);
        }
    }
}
