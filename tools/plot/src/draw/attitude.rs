//! `attitude.png`: roll, pitch and yaw against time, the estimate and (when recorded) truth.

use std::path::Path;

use super::{axis_panels, canvas, estimate_over_truth, fail, nav_and_truth_time_range};
use crate::extract::Extracted;

/// Draws the attitude of `data` into `path`.
pub fn draw(path: &Path, data: &Extracted) -> Result<(), String> {
    let title = if data.truth.is_empty() {
        "Attitude: estimate (no truth in this file)"
    } else {
        "Attitude: estimate and truth"
    };
    let root = canvas(path, title)?;
    let x = nav_and_truth_time_range(data);
    axis_panels(&root, ["roll", "pitch", "yaw"], "deg", x, |axis| {
        estimate_over_truth(
            data,
            |p| (p.t_s, p.euler_deg[axis]),
            |p| (p.t_s, p.euler_deg[axis]),
        )
        .into_iter()
        .map(|line| line.wrapping(180.0))
        .collect()
    })?;
    root.present().map_err(fail)
}
