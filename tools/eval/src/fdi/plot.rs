//! The cross-validated ROC as a PNG: one panel per configuration, false alarms per flight hour
//! against the detection rate of each fault kind, the operating point marked.

use std::path::Path;

use anyhow::{Result, anyhow};
use plotters::prelude::*;

use super::report::OperatingPoint;
use super::roc::RocPoint;

const COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
];

fn plot_error(e: impl std::fmt::Debug) -> anyhow::Error {
    anyhow!("eval fdi: drawing the ROC: {e:?}")
}

/// Draws `points` (every configuration's curve) into `path`.
pub fn draw_roc(path: &Path, points: &[RocPoint], operating: &[OperatingPoint]) -> Result<()> {
    rins_plot::font::register_font();
    let mut configurations: Vec<&'static str> = Vec::new();
    for p in points {
        if !configurations.contains(&p.configuration) {
            configurations.push(p.configuration);
        }
    }
    if configurations.is_empty() {
        return Err(anyhow!("eval fdi: no ROC point to draw"));
    }
    let root =
        BitMapBackend::new(path, (640 * configurations.len() as u32, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(plot_error)?;
    let panels = root.split_evenly((1, configurations.len()));
    for (panel, configuration) in panels.iter().zip(&configurations) {
        let curve: Vec<&RocPoint> = points
            .iter()
            .filter(|p| p.configuration == *configuration)
            .collect();
        let x_max = curve
            .iter()
            .map(|p| p.false_alarms_per_hour)
            .fold(0.0, f64::max)
            .max(1.0)
            * 1.1;
        let mut chart = ChartBuilder::on(panel)
            .caption(
                format!("{configuration}: leave-one-flight-out ROC"),
                ("sans-serif", 20),
            )
            .margin(12)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..x_max, 0.0..1.02)
            .map_err(plot_error)?;
        chart
            .configure_mesh()
            .x_desc("false alarms per flight hour")
            .y_desc("faults detected (fraction)")
            .label_style(("sans-serif", 14))
            .draw()
            .map_err(plot_error)?;
        let kinds = curve.first().map_or(0, |p| p.detection.len());
        for k in 0..kinds {
            let colour = COLOURS[k % COLOURS.len()];
            let series: Vec<(f64, f64)> = curve
                .iter()
                .map(|p| (p.false_alarms_per_hour, p.detection[k].rate))
                .collect();
            let name = curve[0].detection[k].fault.clone();
            chart
                .draw_series(LineSeries::new(series.clone(), colour.stroke_width(2)))
                .map_err(plot_error)?
                .label(name)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
            chart
                .draw_series(series.iter().map(|p| Circle::new(*p, 3, colour.filled())))
                .map_err(plot_error)?;
        }
        if let Some(op) = operating.iter().find(|o| o.configuration == *configuration)
            && let Some(p) = curve
                .iter()
                .find(|p| p.false_alarm_probability == op.setting.false_alarm_probability)
        {
            let x = p.false_alarms_per_hour;
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(x, 0.0), (x, 1.02)],
                    BLACK.stroke_width(1),
                )))
                .map_err(plot_error)?
                .label(format!(
                    "operating point (Pfa {:.0e})",
                    op.setting.false_alarm_probability
                ))
                .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .label_font(("sans-serif", 13))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(plot_error)?;
    }
    root.present().map_err(plot_error)?;
    Ok(())
}
