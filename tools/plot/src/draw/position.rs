//! `position.png`: north, east and down from the first solution's position against time, the
//! estimate and (when recorded) truth, and the track seen from above.

use std::path::Path;

use super::{ESTIMATE, Labels, Line, SIZE, TRUTH, canvas, fail, panel, time_range};
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
    let x = time_range(
        data.nav
            .iter()
            .map(|p| p.t_s)
            .chain(data.truth.iter().map(|p| p.t_s)),
    );
    let axes = ["north", "east", "down"];
    for (axis, area) in left.split_evenly((3, 1)).iter().enumerate() {
        let mut lines = vec![Line::solid(
            "estimate",
            ESTIMATE,
            data.nav.iter().map(|p| (p.t_s, p.ned_m[axis])).collect(),
        )];
        if !data.truth.is_empty() {
            lines.push(Line::solid(
                "truth",
                TRUTH,
                data.truth.iter().map(|p| (p.t_s, p.ned_m[axis])).collect(),
            ));
        }
        // The estimate last: drawn over truth, it stays visible where the two agree.
        lines.rotate_left(1);
        let y = format!("{} (m)", axes[axis]);
        let labels = Labels {
            caption: axes[axis],
            x: "time (s)",
            y: &y,
        };
        panel(area, labels, &lines, Some(x))?;
    }
    let mut track = vec![Line::solid(
        "estimate",
        ESTIMATE,
        data.nav.iter().map(|p| (p.ned_m[1], p.ned_m[0])).collect(),
    )];
    if !data.truth.is_empty() {
        track.push(Line::solid(
            "truth",
            TRUTH,
            data.truth
                .iter()
                .map(|p| (p.ned_m[1], p.ned_m[0]))
                .collect(),
        ));
    }
    track.rotate_left(1);
    let labels = Labels {
        caption: "top view",
        x: "east (m)",
        y: "north (m)",
    };
    panel(&right, labels, &track, None)?;
    root.present().map_err(fail)
}
