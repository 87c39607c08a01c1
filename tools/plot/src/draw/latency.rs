//! `latency.png`: a histogram per pipeline hop, in µs, clipped at the 99.9th percentile (the
//! tail piles up in the last bin) with counts on a log scale, and the median and 99th percentile
//! marked.

use std::path::Path;

use plotters::prelude::*;

use super::{canvas, fail, note};
use crate::extract::{Extracted, Hop};
use crate::font::FAMILY;
use crate::stats::{histogram, percentile};

const BINS: usize = 60;
const BAR: RGBColor = RGBColor(31, 119, 180);
const P50: RGBColor = RGBColor(44, 160, 44);
const P99: RGBColor = RGBColor(214, 39, 40);

/// Draws the latency histograms of `data` into `path`.
pub fn draw(path: &Path, data: &Extracted) -> Result<(), String> {
    let root = canvas(
        path,
        "Latency per hop (clipped at p99.9, counts on a log scale)",
    )?;
    for (hop, area) in data.hops.iter().zip(root.split_evenly((2, 2)).iter()) {
        draw_hop(area, hop)?;
    }
    root.present().map_err(fail)
}

fn draw_hop(area: &super::Area<'_>, hop: &Hop) -> Result<(), String> {
    let mut sorted: Vec<f64> = hop
        .values_us
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .collect();
    sorted.sort_by(f64::total_cmp);
    let (Some(lo), Some(p50), Some(p99), Some(p999)) = (
        sorted.first().copied(),
        percentile(&sorted, 50.0),
        percentile(&sorted, 99.0),
        percentile(&sorted, 99.9),
    ) else {
        return note(
            area,
            &format!("{}: no sample carries both stamps", hop.name),
        );
    };
    let hi = if p999 > lo { p999 } else { lo + 1.0 };
    let counts = histogram(&sorted, lo, hi, BINS);
    let width = (hi - lo) / BINS as f64;
    let max = counts.iter().copied().max().unwrap_or(1).max(1) as f64;
    let floor = 0.8;
    let mut chart = ChartBuilder::on(area)
        .caption(
            format!("{} ({} samples)", hop.name, sorted.len()),
            (FAMILY, 18),
        )
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(65)
        .build_cartesian_2d(lo..hi, (floor..max * 2.0).log_scale())
        .map_err(fail)?;
    chart
        .configure_mesh()
        .x_desc("latency (µs)")
        .y_desc("samples")
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .draw()
        .map_err(fail)?;
    chart
        .draw_series(
            counts
                .iter()
                .enumerate()
                .filter(|(_, c)| **c > 0)
                .map(|(i, c)| {
                    let x0 = lo + i as f64 * width;
                    Rectangle::new([(x0, floor), (x0 + width, *c as f64)], BAR.filled())
                }),
        )
        .map_err(fail)?;
    for (value, colour, name) in [(p50, P50, "p50"), (p99, P99, "p99")] {
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(value, floor), (value, max * 2.0)],
                colour.stroke_width(2),
            )))
            .map_err(fail)?
            .label(format!("{name} = {value:.1} µs"))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FAMILY, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(fail)
}
