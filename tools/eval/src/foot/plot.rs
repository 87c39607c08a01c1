//! One PNG per foot-mounted trial (`rins eval pyshoe|xio --plot DIR`): the estimate and the truth
//! in the horizontal plane, the error over time, and the stance phases the detector found.

use std::path::Path;

use anyhow::{Context, Result, anyhow};
use plotters::prelude::*;

use super::FootMethod;

const ESTIMATE: RGBColor = RGBColor(214, 39, 40);
const TRUTH: RGBColor = RGBColor(31, 119, 180);
const STANCE: RGBColor = RGBColor(44, 160, 44);

/// What is drawn for one trial.
pub struct TrialPlot<'a> {
    /// The trial's name: the file is `<name>.png`.
    pub name: &'a str,
    /// The estimator drawn.
    pub method: FootMethod,
    /// Time per sample, s.
    pub t_s: &'a [f64],
    /// Estimated position per sample (first two axes horizontal), m.
    pub estimate: &'a [[f64; 3]],
    /// Rotation about the vertical applied to the estimate (the metric's alignment), rad.
    pub rotation_rad: f64,
    /// True position per sample (x, y horizontal), when the recording has it.
    pub truth: Option<&'a [[f64; 3]]>,
    /// The detector's decision per sample.
    pub stance: &'a [bool],
}

fn plot_error(e: impl std::fmt::Debug) -> anyhow::Error {
    anyhow!("drawing a trial: {e:?}")
}

fn range(values: impl Iterator<Item = f64> + Clone) -> (f64, f64) {
    let lo = values
        .clone()
        .filter(|v| v.is_finite())
        .fold(f64::INFINITY, f64::min);
    let hi = values
        .filter(|v| v.is_finite())
        .fold(f64::NEG_INFINITY, f64::max);
    if lo.is_finite() && hi.is_finite() && hi > lo {
        (lo, hi)
    } else {
        (-1.0, 1.0)
    }
}

/// Draws `plot` into `dir/<name>.png` (creating `dir`).
pub fn draw_trial(dir: &Path, plot: &TrialPlot) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    rins_plot::font::register_font();
    let path = dir.join(format!("{}.png", plot.name));
    let n = plot
        .estimate
        .len()
        .min(plot.t_s.len())
        .min(plot.stance.len());
    let t0 = plot.t_s.first().copied().unwrap_or(0.0);
    let (s, c) = plot.rotation_rad.sin_cos();
    let origin = plot.estimate.first().copied().unwrap_or([0.0; 3]);
    let estimate: Vec<(f64, f64)> = plot.estimate[..n]
        .iter()
        .map(|p| {
            let (x, y) = (p[0] - origin[0], p[1] - origin[1]);
            (c * x - s * y, s * x + c * y)
        })
        .collect();
    let truth: Option<Vec<(f64, f64)>> = plot.truth.map(|t| {
        let o = t.first().copied().unwrap_or([0.0; 3]);
        t.iter()
            .take(n)
            .map(|p| (p[0] - o[0], p[1] - o[1]))
            .collect()
    });
    let root = BitMapBackend::new(&path, (1200, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let (top, bottom) = root.split_vertically(560);
    let (error_area, stance_area) = bottom.split_vertically(200);

    // The horizontal plane, equal scales.
    let all = estimate.iter().chain(truth.iter().flatten());
    let (x0, x1) = range(all.clone().map(|p| p.0));
    let (y0, y1) = range(all.map(|p| p.1));
    let half = 0.55 * (x1 - x0).max(y1 - y0);
    let (cx, cy) = ((x0 + x1) / 2.0, (y0 + y1) / 2.0);
    let method = match plot.method {
        FootMethod::Rins => "rins",
        FootMethod::Reference => "peer's method",
    };
    let mut chart = ChartBuilder::on(&top)
        .caption(format!("{}: {method}", plot.name), ("sans-serif", 22))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(50)
        .build_cartesian_2d(cx - half * 1.6..cx + half * 1.6, cy - half..cy + half)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("x, m")
        .y_desc("y, m")
        .draw()
        .map_err(plot_error)?;
    // The truth (when there is one) under the estimate.
    let tracks = truth
        .iter()
        .map(|t| ("truth", t, TRUTH, 2))
        .chain([("estimate", &estimate, ESTIMATE, 1)]);
    for (name, track, colour, width) in tracks {
        chart
            .draw_series(LineSeries::new(
                track.iter().copied(),
                colour.stroke_width(width),
            ))
            .map_err(plot_error)?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(plot_error)?;

    let t_end = plot
        .t_s
        .get(n.saturating_sub(1))
        .map_or(1.0, |t| t - t0)
        .max(1e-3);
    // Horizontal error over time (or, without truth, the distance from the start).
    let (label, series): (&str, Vec<(f64, f64)>) = match &truth {
        Some(truth) => (
            "horizontal error, m",
            (0..n)
                .map(|k| {
                    let (e, t) = (estimate[k], truth[k]);
                    (plot.t_s[k] - t0, (e.0 - t.0).hypot(e.1 - t.1))
                })
                .collect(),
        ),
        None => (
            "distance from the start, m",
            (0..n)
                .map(|k| (plot.t_s[k] - t0, estimate[k].0.hypot(estimate[k].1)))
                .collect(),
        ),
    };
    let (_, e_max) = range(series.iter().map(|p| p.1).chain([0.0]));
    let mut chart = ChartBuilder::on(&error_area)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..t_end, 0.0..e_max * 1.05)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .y_desc(label)
        .draw()
        .map_err(plot_error)?;
    chart
        .draw_series(LineSeries::new(series, ESTIMATE))
        .map_err(plot_error)?;

    // Stance phases.
    let mut chart = ChartBuilder::on(&stance_area)
        .margin(10)
        .x_label_area_size(30)
        .y_label_area_size(50)
        .build_cartesian_2d(0.0..t_end, 0.0..1.2)
        .map_err(plot_error)?;
    chart
        .configure_mesh()
        .x_desc("time, s")
        .y_desc("stance")
        .y_labels(2)
        .draw()
        .map_err(plot_error)?;
    chart
        .draw_series(LineSeries::new(
            (0..n).map(|k| (plot.t_s[k] - t0, f64::from(u8::from(plot.stance[k])))),
            STANCE,
        ))
        .map_err(plot_error)?;
    root.present().map_err(plot_error)?;
    Ok(())
}
