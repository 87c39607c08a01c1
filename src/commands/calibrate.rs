//! `rins calibrate mag FILE`: magnetometer hard and soft iron from recorded samples
//! ([`rins_navigator::mag_calibration`]), printed as a summary and as the configuration fragment
//! that applies it.
//!
//! The file is a CSV with a header line. Its columns are found by name, so the output of
//! `rins echo raw-mag --csv` can be used as it is (`field_ut.0,field_ut.1,field_ut.2` among the
//! header and sequence columns), as can a plain `mx_ut,my_ut,mz_ut` file from another tool.

use anyhow::{Context, Result, anyhow, bail};
use rins_navigator::mag_calibration::{MagCalibration, MagCalibrationError, MagFit, fit_ellipsoid};
use serde::Serialize;

use crate::cli::CalibrateMagArgs;

/// Column sets a magnetometer CSV may carry, in order of preference.
const COLUMN_SETS: [[&str; 3]; 2] = [
    ["field_ut.0", "field_ut.1", "field_ut.2"],
    ["mx_ut", "my_ut", "mz_ut"],
];

/// Samples of a file with the line each came from, for errors that point at it.
#[derive(Debug)]
struct Samples {
    points: Vec<[f64; 3]>,
    lines: Vec<usize>,
}

/// Parses the CSV `text`; errors name `source:line`.
fn parse_samples(text: &str, source: &str) -> Result<Samples> {
    let mut rows = text
        .lines()
        .enumerate()
        .map(|(i, line)| (i + 1, line.trim_start_matches('\u{feff}').trim()))
        .filter(|(_, line)| !line.is_empty());
    let Some((header_line, header)) = rows.next() else {
        bail!("{source}: empty file: expected a CSV header line and samples");
    };
    let names: Vec<&str> = header.split(',').map(str::trim).collect();
    let position = |name: &str| names.iter().position(|n| *n == name);
    let Some((columns, indices)) = COLUMN_SETS.iter().find_map(|set| {
        let indices = [position(set[0])?, position(set[1])?, position(set[2])?];
        Some((set, indices))
    }) else {
        bail!(
            "{source}:{header_line}: the header has neither field_ut.0,field_ut.1,field_ut.2 \
             (`rins echo raw-mag --csv`) nor mx_ut,my_ut,mz_ut columns: {header:?}"
        );
    };
    let mut samples = Samples {
        points: Vec::new(),
        lines: Vec::new(),
    };
    for (line, row) in rows {
        let cells: Vec<&str> = row.split(',').map(str::trim).collect();
        if cells.len() != names.len() {
            bail!(
                "{source}:{line}: {} fields, the header (line {header_line}) has {}",
                cells.len(),
                names.len()
            );
        }
        let mut point = [0.0; 3];
        for ((value, &index), column) in point.iter_mut().zip(&indices).zip(columns) {
            let cell = cells[index];
            *value = cell
                .parse::<f64>()
                .map_err(|_| anyhow!("{source}:{line}: {column} = {cell:?}: not a number"))?;
            if !value.is_finite() {
                bail!("{source}:{line}: {column} = {cell}: must be finite");
            }
        }
        samples.points.push(point);
        samples.lines.push(line);
    }
    Ok(samples)
}

/// The configuration fragment that applies `calibration`.
fn config_fragment(calibration: &MagCalibration) -> String {
    let row = |v: &[f64; 3], digits: usize| {
        format!("[{:.digits$}, {:.digits$}, {:.digits$}]", v[0], v[1], v[2])
    };
    let w = &calibration.soft_iron_correction;
    format!(
        "[navigator.mag_calibration]\nhard_iron_ut = {}\nsoft_iron_correction = [{}, {}, {}]\n",
        row(&calibration.hard_iron_ut, 4),
        row(&w[0], 6),
        row(&w[1], 6),
        row(&w[2], 6)
    )
}

/// What `--json` prints.
#[derive(Serialize)]
struct Report<'a> {
    file: &'a str,
    samples: usize,
    field_ut: f64,
    field_given: bool,
    hard_iron_ut: [f64; 3],
    soft_iron_correction: [[f64; 3]; 3],
    residual_rms_ut: f64,
    residual_max_ut: f64,
    direction_spread: f64,
    config: String,
}

fn print_text(file: &str, fit: &MagFit, fragment: &str) {
    let c = &fit.calibration;
    let source = if fit.field_given {
        "given"
    } else {
        "mean of the samples without hard iron"
    };
    println!(
        "magnetometer calibration from {} samples of {file}",
        fit.samples
    );
    println!("  field magnitude F: {:.3} µT ({source})", fit.field_ut);
    let b = c.hard_iron_ut;
    println!("  hard iron b: [{:.3}, {:.3}, {:.3}] µT", b[0], b[1], b[2]);
    println!("  soft-iron correction W (h = W (m − b)):");
    for r in &c.soft_iron_correction {
        println!("    [{:9.6}, {:9.6}, {:9.6}]", r[0], r[1], r[2]);
    }
    println!(
        "  residual |W (m − b)| − F: RMS {:.3} µT, max {:.3} µT",
        fit.residual_rms_ut, fit.residual_max_ut
    );
    println!(
        "  direction spread: {:.3} (smallest variance of the field directions; 0.333 = whole sphere)",
        fit.direction_spread
    );
    println!();
    print!("{fragment}");
}

pub fn run_mag(args: &CalibrateMagArgs) -> Result<()> {
    if let Some(f) = args.field_ut
        && !(f.is_finite() && f > 0.0)
    {
        bail!("--field-ut {f}: must be a positive number of microtesla");
    }
    let file = args.file.display().to_string();
    let text = std::fs::read_to_string(&args.file)
        .with_context(|| format!("cannot read magnetometer samples {file}"))?;
    let samples = parse_samples(&text, &file)?;
    let fit = fit_ellipsoid(&samples.points, args.field_ut).map_err(|e| match e {
        MagCalibrationError::SampleOutOfRange { index, .. } => {
            let line = samples.lines.get(index).copied().unwrap_or_default();
            anyhow!("{file}:{line}: {e}")
        }
        _ => anyhow!("{file}: {e}"),
    })?;
    let fragment = config_fragment(&fit.calibration);
    if args.json {
        let report = Report {
            file: &file,
            samples: fit.samples,
            field_ut: fit.field_ut,
            field_given: fit.field_given,
            hard_iron_ut: fit.calibration.hard_iron_ut,
            soft_iron_correction: fit.calibration.soft_iron_correction,
            residual_rms_ut: fit.residual_rms_ut,
            residual_max_ut: fit.residual_max_ut,
            direction_spread: fit.direction_spread,
            config: fragment,
        };
        println!("{}", serde_json::to_string(&report)?);
    } else {
        print_text(&file, &fit, &fragment);
    }
    Ok(())
}
