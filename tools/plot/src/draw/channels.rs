//! `channels.png`: one time line per gyro and accelerometer channel, coloured by the state fusion
//! gave it, with the injected faults and the lane switches marked.

use std::path::Path;

use ipc_types::ChannelState;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

use super::{canvas, fail, time_range};
use crate::extract::{Extracted, Marker};
use crate::font::FAMILY;

/// The colour of a channel state; grey for a value this build does not know.
fn colour(state: u8) -> RGBColor {
    match ChannelState::from_u8(state) {
        Some(ChannelState::Ok) => RGBColor(44, 160, 44),
        Some(ChannelState::Suspect) => RGBColor(255, 187, 0),
        Some(ChannelState::Excluded) => RGBColor(214, 39, 40),
        Some(ChannelState::Absent) => RGBColor(200, 200, 200),
        None => RGBColor(90, 90, 90),
    }
}

const FAULT: RGBColor = RGBColor(148, 103, 189);
const LANE: RGBColor = RGBColor(31, 119, 180);

/// Draws the channel states of `data` into `path`.
pub fn draw(path: &Path, data: &Extracted) -> Result<(), String> {
    let root = canvas(
        path,
        "Redundant channels: state per channel, faults injected and lane switches",
    )?;
    let rows = data.channels.len();
    let x = time_range(
        data.channels
            .iter()
            .flat_map(|c| c.runs.iter().flat_map(|r| [r.start_s, r.end_s]))
            .chain(data.faults.iter().map(|m| m.t_s))
            .chain(data.lane_switches.iter().map(|m| m.t_s)),
    );
    // Row k is centred on y = rows − 1 − k, so that the first gyro is at the top; three more
    // rows above hold the event labels.
    let top = rows as f64 + 2.5;
    let mut chart = ChartBuilder::on(&root)
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d(x.0..x.1, -0.5..top)
        .map_err(fail)?;
    let names: Vec<String> = data.channels.iter().map(|c| c.name.clone()).collect();
    let label_of = move |y: &f64| {
        let k = rows as f64 - 1.0 - y.round();
        if (y - y.round()).abs() < 0.01 && k >= 0.0 && (k as usize) < names.len() {
            names[k as usize].clone()
        } else {
            String::new()
        }
    };
    chart
        .configure_mesh()
        .disable_y_mesh()
        .y_labels(rows + 3)
        .y_label_formatter(&label_of)
        .x_desc("time (s)")
        .y_desc("channel")
        .label_style((FAMILY, 13))
        .axis_desc_style((FAMILY, 14))
        .draw()
        .map_err(fail)?;
    for (k, row) in data.channels.iter().enumerate() {
        let y = (rows - 1 - k) as f64;
        chart
            .draw_series(row.runs.iter().map(|r| {
                Rectangle::new(
                    [(r.start_s, y - 0.35), (r.end_s, y + 0.35)],
                    colour(r.state).filled(),
                )
            }))
            .map_err(fail)?;
    }
    for state in ChannelState::ALL {
        let c = colour(state as u8);
        chart
            .draw_series(std::iter::empty::<Rectangle<(f64, f64)>>())
            .map_err(fail)?
            .label(state.name())
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 18, y + 5)], c.filled()));
    }
    draw_markers(&mut chart, &data.faults, FAULT, "fault injected", rows, top)?;
    draw_markers(
        &mut chart,
        &data.lane_switches,
        LANE,
        "lane switch",
        rows,
        top,
    )?;
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .label_font((FAMILY, 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(fail)?;
    root.present().map_err(fail)
}

/// Vertical lines at each marker with its label above the rows, staggered over three lines so
/// that close events stay legible.
fn draw_markers<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    markers: &[Marker],
    colour: RGBColor,
    legend: &str,
    rows: usize,
    top: f64,
) -> Result<(), String> {
    if markers.is_empty() {
        return Ok(());
    }
    let bottom = -0.5;
    chart
        .draw_series(
            markers.iter().map(|m| {
                PathElement::new(vec![(m.t_s, bottom), (m.t_s, top)], colour.stroke_width(2))
            }),
        )
        .map_err(|e| format!("drawing failed: {e:?}"))?
        .label(legend)
        .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
    let style = TextStyle::from((FAMILY, 14).into_font()).color(&colour);
    chart
        .draw_series(markers.iter().enumerate().map(|(i, m)| {
            let y = rows as f64 - 0.2 + (i % 3) as f64 * 0.9;
            Text::new(format!(" {}", m.label), (m.t_s, y), style.clone())
        }))
        .map_err(|e| format!("drawing failed: {e:?}"))?;
    Ok(())
}
