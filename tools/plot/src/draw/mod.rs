//! Drawing: one module per PNG, and the panel they share (time series with a legend, NaN and
//! wrap-arounds left undrawn, long series thinned).

pub mod attitude;
pub mod channels;
pub mod errors;
pub mod latency;
pub mod position;

use std::fmt::Debug;

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::extract::{Extracted, NavPoint, TruthPoint};
use crate::font::FAMILY;
use crate::stats::{finite_bounds, finite_runs, padded, thin};

/// Width and height of every PNG, pixels.
pub const SIZE: (u32, u32) = (1400, 900);

/// At most this many points of a series are drawn.
pub const MAX_POINTS: usize = 5000;

/// The estimate's colour.
pub const ESTIMATE: RGBColor = RGBColor(31, 119, 180);
/// Truth's colour.
pub const TRUTH: RGBColor = RGBColor(255, 127, 14);
/// The 3σ bounds' colour.
pub const BOUND: RGBColor = RGBColor(110, 110, 110);
/// An error's colour.
pub const ERROR: RGBColor = RGBColor(214, 39, 40);

/// A drawing area of a bitmap.
pub type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// A drawing failure, as text for the report.
pub fn fail(e: impl Debug) -> String {
    format!("drawing failed: {e:?}")
}

/// One series of a panel.
#[derive(Debug, Clone)]
pub struct Line {
    /// Legend text; empty for none (the second half of a ± bound).
    pub label: String,
    /// Colour.
    pub colour: RGBColor,
    /// (x, y) points; non-finite ones are not drawn.
    pub points: Vec<(f64, f64)>,
    /// Drawn dashed (bounds).
    pub dashed: bool,
    /// A jump larger than this between neighbours is not drawn (angles wrapping at ±180°).
    pub wrap: Option<f64>,
}

impl Line {
    /// A solid line.
    pub fn solid(label: impl Into<String>, colour: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            label: label.into(),
            colour,
            points,
            dashed: false,
            wrap: None,
        }
    }

    /// A dashed line.
    pub fn dashed(label: impl Into<String>, colour: RGBColor, points: Vec<(f64, f64)>) -> Self {
        Self {
            dashed: true,
            ..Self::solid(label, colour, points)
        }
    }

    /// The same line, with jumps beyond `limit` left undrawn.
    pub fn wrapping(mut self, limit: f64) -> Self {
        self.wrap = Some(limit);
        self
    }
}

/// A panel's texts.
#[derive(Debug, Clone, Copy)]
pub struct Labels<'a> {
    /// Caption above the panel.
    pub caption: &'a str,
    /// X axis description, with unit.
    pub x: &'a str,
    /// Y axis description, with unit.
    pub y: &'a str,
}

/// A new PNG of [`SIZE`] at `path`, white, with `title` on top; the area below the title.
pub fn canvas<'a>(path: &'a std::path::Path, title: &str) -> Result<Area<'a>, String> {
    let root = BitMapBackend::new(path, SIZE).into_drawing_area();
    root.fill(&WHITE).map_err(fail)?;
    root.titled(title, (FAMILY, 26)).map_err(fail)
}

/// Draws `lines` in `area` as one x–y panel; `x_range` fixes the x axis (a shared time axis), by
/// default it spans the data.
pub fn panel(
    area: &Area<'_>,
    labels: Labels<'_>,
    lines: &[Line],
    x_range: Option<(f64, f64)>,
) -> Result<(), String> {
    let thinned: Vec<Vec<(f64, f64)>> = lines.iter().map(|l| thin(&l.points, MAX_POINTS)).collect();
    let all = || thinned.iter().flatten();
    let (x0, x1) = x_range.unwrap_or_else(|| padded(finite_bounds(all().map(|p| p.0))));
    let (y0, y1) = padded(finite_bounds(
        all().filter(|p| p.0 >= x0 && p.0 <= x1).map(|p| p.1),
    ));
    let mut chart = ChartBuilder::on(area)
        .caption(labels.caption, (FAMILY, 18))
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(65)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(fail)?;
    chart
        .configure_mesh()
        .x_desc(labels.x)
        .y_desc(labels.y)
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .draw()
        .map_err(fail)?;
    let mut legend = false;
    for (line, points) in lines.iter().zip(&thinned) {
        let colour = line.colour;
        let style = colour.stroke_width(if line.dashed { 1 } else { 2 });
        let mut labelled = line.label.is_empty();
        for run in finite_runs(points, line.wrap) {
            let anno = if line.dashed {
                chart
                    .draw_series(DashedLineSeries::new(run, 6, 4, style))
                    .map_err(fail)?
            } else if run.len() == 1 {
                chart
                    .draw_series(run.into_iter().map(|p| Circle::new(p, 2, colour.filled())))
                    .map_err(fail)?
            } else {
                chart
                    .draw_series(LineSeries::new(run, style))
                    .map_err(fail)?
            };
            if !labelled {
                anno.label(line.label.clone()).legend(move |(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
                });
                labelled = true;
                legend = true;
            }
        }
    }
    if legend {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font((FAMILY, 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(fail)?;
    }
    Ok(())
}

/// A panel with nothing to draw but a sentence.
pub fn note(area: &Area<'_>, text: &str) -> Result<(), String> {
    let (_, h) = area.dim_in_pixel();
    area.draw(&Text::new(
        text.to_string(),
        (20, i32::try_from(h / 2).unwrap_or(0)),
        (FAMILY, 16).into_font(),
    ))
    .map_err(fail)?;
    Ok(())
}

/// The time span of every series given, padded.
pub fn time_range(times: impl IntoIterator<Item = f64>) -> (f64, f64) {
    padded(finite_bounds(times))
}

/// The time span of the navigation output and the truth together, padded.
pub fn nav_and_truth_time_range(data: &Extracted) -> (f64, f64) {
    time_range(
        data.nav
            .iter()
            .map(|p| p.t_s)
            .chain(data.truth.iter().map(|p| p.t_s)),
    )
}

/// The estimate's points `nav` makes of each solution and, when recorded, truth's that `truth`
/// makes of each true state, as the lines of one panel: truth first, so that the estimate drawn
/// over it stays visible where the two agree.
pub fn estimate_over_truth(
    data: &Extracted,
    nav: impl Fn(&NavPoint) -> (f64, f64),
    truth: impl Fn(&TruthPoint) -> (f64, f64),
) -> Vec<Line> {
    let estimate = Line::solid("estimate", ESTIMATE, data.nav.iter().map(nav).collect());
    let truth = (!data.truth.is_empty())
        .then(|| Line::solid("truth", TRUTH, data.truth.iter().map(truth).collect()));
    truth.into_iter().chain([estimate]).collect()
}

/// Three panels stacked in `area`, one per name in `axes`, of the lines `lines_of` gives for
/// that axis against time over `x`; `unit` on the y labels.
pub fn axis_panels(
    area: &Area<'_>,
    axes: [&str; 3],
    unit: &str,
    x: (f64, f64),
    lines_of: impl Fn(usize) -> Vec<Line>,
) -> Result<(), String> {
    for (axis, cell) in area.split_evenly((3, 1)).iter().enumerate() {
        let y = format!("{} ({unit})", axes[axis]);
        let labels = Labels {
            caption: axes[axis],
            x: "time (s)",
            y: &y,
        };
        panel(cell, labels, &lines_of(axis), Some(x))?;
    }
    Ok(())
}
