//! The x-io gait-tracking walks: a foot-mounted NGIMU at about 400 Hz, walked in closed loops
//! (the foot ends where it started), so the distance between the start and end positions is the
//! error.
//!
//! Header [`HEADER`]: time s, rate °/s, specific force in g. The NGIMU's z axis points up (at
//! rest the accelerometer reads `z ≈ +0.83 g` on the tilted foot), so both vectors are turned
//! 180° about x into the z-down convention: `(x, y, z) → (x, −y, −z)`, a proper rotation. The
//! files repeat some rows with the same time stamp; those are dropped and counted.

use std::path::Path;

use super::DatasetError;
use super::csv::parse_numeric;
use super::foot::{
    FootSample, FootTrial, PeerResult, assemble, data_lines, read_text, stem, turn_about_x,
};

/// The header of a walk file.
pub const HEADER: [&str; 7] = [
    "Time (s)",
    "Gyroscope X (deg/s)",
    "Gyroscope Y (deg/s)",
    "Gyroscope Z (deg/s)",
    "Accelerometer X (g)",
    "Accelerometer Y (g)",
    "Accelerometer Z (g)",
];

/// Standard gravity, the unit of the accelerometer columns, m/s².
pub const G0_MPS2: f64 = rins_earth::STANDARD_GRAVITY;

/// The published end-point error of a walk, m, by file stem: 0.082 m after ~25 m for
/// `short_walk`, 0.421 m after ~60 m for `long_walk`; `None` for any other name.
pub fn peer_end_error_m(stem: &str) -> Option<f64> {
    match stem {
        "short_walk" => Some(0.082),
        "long_walk" => Some(0.421),
        _ => None,
    }
}

/// One file row in the z-down convention and SI units.
fn sample_from_row(r: &[f64; 7]) -> FootSample {
    FootSample {
        t_s: r[0],
        gyro_rps: turn_about_x([r[1], r[2], r[3]].map(f64::to_radians)),
        accel_mps2: turn_about_x([r[4], r[5], r[6]].map(|g| g * G0_MPS2)),
    }
}

/// Loads one walk; the peer figure is looked up by the file stem.
pub fn load_walk(path: &Path) -> Result<FootTrial, DatasetError> {
    let text = read_text(path, "x-io walk; `rins data fetch xio-gait` downloads it")?;
    parse_walk(path, &text)
}

/// [`load_walk`] on the text already read; `path` names the walk and the errors.
pub(crate) fn parse_walk(path: &Path, text: &str) -> Result<FootTrial, DatasetError> {
    let rows = parse_numeric(path, text, &HEADER)?;
    let samples = rows.iter().map(sample_from_row).collect();
    let peer = peer_end_error_m(&stem(path)).map(PeerResult::EndErrorM);
    assemble(path, samples, &data_lines(text), None, peer)
}

#[cfg(test)]
mod tests {
    use std::f64::consts::FRAC_PI_2;

    use super::*;

    /// A still walk of `seconds` at 400 Hz lying level, z up: accel `+1 g` on z.
    fn walk_text(seconds: f64) -> String {
        crate::datasets::csv::still_rows(&HEADER, 400.0, seconds, 0, "0.1,-0.2,0.3,0.01,-0.02,1")
    }

    #[test]
    fn rows_turn_into_z_down_si_samples() {
        let s = sample_from_row(&[0.5, 0.0, 90.0, 0.0, 0.0, 0.0, 1.0]);
        assert_eq!(s.t_s, 0.5);
        assert!(
            (s.gyro_rps[1] + FRAC_PI_2).abs() < 1e-12,
            "{:?}",
            s.gyro_rps
        );
        assert_eq!(s.accel_mps2[2], -9.80665);
        let s = sample_from_row(&[0.0, 180.0, 0.0, -45.0, 0.5, -0.25, 0.0]);
        let expected_gyro = [std::f64::consts::PI, 0.0, std::f64::consts::FRAC_PI_4];
        for (got, want) in s.gyro_rps.iter().zip(expected_gyro) {
            assert!((got - want).abs() < 1e-12, "{:?}", s.gyro_rps);
        }
        assert_eq!(s.accel_mps2, [0.5 * G0_MPS2, 0.25 * G0_MPS2, 0.0]);
    }

    #[test]
    fn a_level_still_walk_reads_minus_g_on_z() {
        let trial = parse_walk(Path::new("d/short_walk.csv"), &walk_text(2.5)).unwrap();
        assert_eq!(trial.name, "short_walk");
        assert_eq!(trial.samples.len(), 1001);
        assert_eq!(trial.samples[0].accel_mps2[2], -G0_MPS2);
        assert_eq!(trial.truth_m, None);
        assert_eq!(trial.peer, Some(PeerResult::EndErrorM(0.082)));
        assert!((trial.rate_hz - 400.0).abs() < 1e-6, "{}", trial.rate_hz);
        let other = parse_walk(Path::new("d/my_walk.csv"), &walk_text(2.5)).unwrap();
        assert_eq!(other.peer, None);
        assert_eq!(peer_end_error_m("long_walk"), Some(0.421));
    }

    #[test]
    fn repeated_rows_are_dropped_and_counted() {
        let mut lines: Vec<String> = walk_text(3.0).lines().map(str::to_owned).collect();
        // Line 2 is t = 0; repeat the rows at t = 0 and t = 0.0025 (identical, as in the files),
        // and one row at t = 0.005 with different values.
        lines.insert(2, lines[1].clone());
        lines.insert(4, lines[3].clone());
        lines.insert(6, lines[5].replace(",1", ",0.9"));
        let text = lines.join("\n") + "\n";
        let trial = parse_walk(Path::new("d/long_walk.csv"), &text).unwrap();
        assert_eq!(trial.dropped_duplicates, 3);
        assert_eq!(trial.samples.len(), 1201);
        assert_eq!(trial.samples[2].accel_mps2[2], -G0_MPS2);
        assert!(trial.samples.windows(2).all(|w| w[1].t_s > w[0].t_s));
    }

    #[test]
    fn time_going_back_is_refused_at_its_line() {
        let text = walk_text(3.0) + "\n2.5,0,0,0,0,0,1\n";
        let e = parse_walk(Path::new("d/w.csv"), &text).unwrap_err();
        assert_eq!(e.to_string(), "d/w.csv:1204: time 2.5 s goes back from 3 s");
    }

    #[test]
    fn header_short_and_missing_file_errors_name_the_file() {
        let text = walk_text(3.0).replacen("(deg/s)", "(rad/s)", 1);
        let e = parse_walk(Path::new("d/w.csv"), &text).unwrap_err();
        assert!(matches!(e, DatasetError::Header { .. }), "{e}");
        assert!(e.to_string().starts_with("d/w.csv:1: header"), "{e}");
        let e = parse_walk(Path::new("d/w.csv"), &walk_text(1.5)).unwrap_err();
        assert_eq!(e.to_string(), "d/w.csv: 601 data rows, need at least 801");
        let e = load_walk(Path::new("/nonexistent/rins/short_walk.csv")).unwrap_err();
        assert!(matches!(e, DatasetError::MissingFile { .. }), "{e}");
        assert!(
            e.to_string()
                .starts_with("/nonexistent/rins/short_walk.csv"),
            "{e}"
        );
    }
}
