//! `position.png`: north, east and down from the first solution's position against time, the
//! estimate and (when recorded) truth, and the track seen from above.

use std::path::Path;

use super::{
    Labels, SIZE, axis_panels, canvas, estimate_over_truth, fail, nav_and_truth_time_range, panel,
};
use crate::extract::Extracted;

/// Draws the position of `data` into `path`.
pub fn draw(path: &Path, data: &Extracted) -> Result<(), String> {
    let title = if data.truth.is_empty() {
        "Position from the first solution: estimate (no truth in this file)"
    } else {
        "Position from the first solution: estimate and truth"
    };
    let root = canvas(path, title)?;
    let (left, right) = root.split_horizontally(SIZE.0 * 3 / 5);
    let x = nav_and_truth_time_range(data);
    axis_panels(&left, ["north", "east", "down"], "m", x, |axis| {
        estimate_over_truth(data, |p| (p.t_s, p.ned_m[axis]), |p| (p.t_s, p.ned_m[axis]))
    })?;
    let track = estimate_over_truth(
        data,
        |p| (p.ned_m[1], p.ned_m[0]),
        |p| (p.ned_m[1], p.ned_m[0]),
    );
    let labels = Labels {
        caption: "top view",
        x: "east (m)",
        y: "north (m)",
    };
    panel(&right, labels, &track, None)?;
    root.present().map_err(fail)
}
