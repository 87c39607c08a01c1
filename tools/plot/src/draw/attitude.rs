//! `attitude.png`: roll, pitch and yaw against time, the estimate and (when recorded) truth.

use std::path::Path;

use super::{ESTIMATE, Labels, Line, TRUTH, canvas, fail, panel, time_range};
use crate::extract::Extracted;

/// Draws the attitude of `data` into `path`.
pub fn draw(path: &Path, data: &Extracted) -> Result<(), String> {
    let title = if data.truth.is_empty() {
        "Attitude: estimate (no truth in this file)"
    } else {
        "Attitude: estimate and truth"
    };
    let root = canvas(path, title)?;
    let x = time_range(
        data.nav
            .iter()
            .map(|p| p.t_s)
            .chain(data.truth.iter().map(|p| p.t_s)),
    );
    let axes = ["roll", "pitch", "yaw"];
    for (axis, area) in root.split_evenly((3, 1)).iter().enumerate() {
        let mut lines = vec![
            Line::solid(
                "estimate",
                ESTIMATE,
                data.nav
                    .iter()
                    .map(|p| (p.t_s, p.euler_deg[axis]))
                    .collect(),
            )
            .wrapping(180.0),
        ];
        if !data.truth.is_empty() {
            lines.push(
                Line::solid(
                    "truth",
                    TRUTH,
                    data.truth
                        .iter()
                        .map(|p| (p.t_s, p.euler_deg[axis]))
                        .collect(),
                )
                .wrapping(180.0),
            );
        }
        // The estimate last: drawn over truth, it stays visible where the two agree.
        lines.rotate_left(1);
        let y = format!("{} (deg)", axes[axis]);
        let labels = Labels {
            caption: axes[axis],
            x: "time (s)",
            y: &y,
        };
        panel(area, labels, &lines, Some(x))?;
    }
    root.present().map_err(fail)
}
