//! Plots of a rins recording as PNG files, and the font every rins plot draws its text with.
//!
//! [`plot_recording`] reads an MCAP recording one message at a time ([`extract`]) and draws
//! (see [`draw`]):
//!
//! - `attitude.png`: roll, pitch, yaw of the navigation solution, and truth when recorded;
//! - `position.png`: north, east, down from the first solution, and the track from above;
//! - `errors.png`: attitude and position errors against truth with the filter's 3σ bounds;
//! - `channels.png`: the state of every redundant channel, the faults injected, the lane switches;
//! - `latency.png`: a histogram of each pipeline hop.
//!
//! A plot whose topics the file lacks is skipped with the reason, and so is one that fails to
//! draw: the others are still drawn. Pure helpers ([`compare`], [`stats`]) do the arithmetic.

pub mod compare;
pub mod draw;
pub mod extract;
pub mod font;
pub mod stats;

use std::path::{Path, PathBuf};

use ipc_types::names;
use rins_recording::{Messages, ReadError};

use extract::{Collector, Extracted};

/// What [`plot_recording`] did.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PlotReport {
    /// The PNG files written.
    pub written: Vec<PathBuf>,
    /// The plots not drawn: (file name, why).
    pub skipped: Vec<(String, String)>,
    /// Messages the reader skipped as damaged.
    pub damaged_messages: u64,
    /// Chunks the reader skipped as damaged (their messages are lost, and not counted above).
    pub damaged_chunks: u64,
    /// Where reading stopped early (a cut-off file), if it did.
    pub damage: Option<String>,
}

/// Why nothing could be plotted.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The recording could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// The output directory is not usable.
    #[error("output directory {path}: {reason}")]
    Output {
        /// The directory given.
        path: PathBuf,
        /// What is wrong with it.
        reason: String,
    },
}

/// A plot: its file name, the topics it needs (any one of them), and how to draw it.
struct Plot {
    file: &'static str,
    needs: &'static [&'static str],
    draw: fn(&Path, &Extracted) -> Result<(), String>,
}

const PLOTS: [Plot; 5] = [
    Plot {
        file: "attitude.png",
        needs: &names::NAV_LANES,
        draw: draw::attitude::draw,
    },
    Plot {
        file: "position.png",
        needs: &names::NAV_LANES,
        draw: draw::position::draw,
    },
    Plot {
        file: "errors.png",
        needs: &names::NAV_LANES,
        draw: draw::errors::draw,
    },
    Plot {
        file: "channels.png",
        needs: &[names::FUSED_IMU],
        draw: draw::channels::draw,
    },
    Plot {
        file: "latency.png",
        needs: &[names::NAV_LANES[0], names::NAV_LANES[1], names::FUSED_IMU],
        draw: draw::latency::draw,
    },
];

/// Messages between two progress reports while reading.
const PROGRESS_EVERY: u64 = 200_000;

/// Reads the recording at `path` and writes the plots into the directory `out` (created if
/// missing; a symbolic link or a file there is refused). `progress` hears what is being done,
/// one line at a time.
pub fn plot_recording(
    path: &Path,
    out: &Path,
    mut progress: impl FnMut(&str),
) -> Result<PlotReport, PlotError> {
    prepare_output(out)?;
    progress(&format!("reading {}", path.display()));
    // A regular file of bounded size: a FIFO, a device or a directory is refused at once.
    let bytes = rins_recording::read_file_bytes(path)?;
    let mut messages = Messages::new(&bytes, &path.display().to_string())?;
    let mut collector = Collector::default();
    let mut count = 0u64;
    for message in &mut messages {
        collector.add(&message?);
        count += 1;
        if count.is_multiple_of(PROGRESS_EVERY) {
            progress(&format!("read {count} messages"));
        }
    }
    let mut report = PlotReport {
        damaged_messages: messages.skipped_count(),
        damaged_chunks: messages.damaged_chunk_count(),
        damage: messages.damage().map(str::to_string),
        ..PlotReport::default()
    };
    drop(bytes);
    progress(&format!("read {count} messages"));
    let data = collector.finish();
    font::register_font();
    for plot in &PLOTS {
        if let Some(reason) = missing(plot, &data) {
            report.skipped.push((plot.file.to_string(), reason));
            continue;
        }
        progress(&format!("drawing {}", plot.file));
        let file = out.join(plot.file);
        match (plot.draw)(&file, &data) {
            Ok(()) => report.written.push(file),
            Err(reason) => report.skipped.push((plot.file.to_string(), reason)),
        }
    }
    Ok(report)
}

/// Why `plot` cannot be drawn from `data`, `None` when it can.
fn missing(plot: &Plot, data: &Extracted) -> Option<String> {
    if !plot.needs.iter().any(|t| data.topics.contains(*t)) {
        return Some(format!("no {} in this file", plot.needs.join(" or ")));
    }
    match plot.file {
        "attitude.png" | "position.png" | "errors.png" if data.nav.is_empty() => Some(format!(
            "no usable navigation solution in this file ({} samples aligning or invalid)",
            data.nav_unusable
        )),
        "channels.png" if data.channels.is_empty() => {
            Some(format!("{} fits no channel", names::FUSED_IMU))
        }
        "latency.png" if data.hops.iter().all(|h| h.values_us.is_empty()) => {
            Some("no sample carries two stage stamps".to_string())
        }
        _ => None,
    }
}

/// Creates `out` if missing; refuses a symbolic link, or anything but a directory.
fn prepare_output(out: &Path) -> Result<(), PlotError> {
    let refuse = |reason: String| PlotError::Output {
        path: out.to_path_buf(),
        reason,
    };
    match std::fs::symlink_metadata(out) {
        Ok(meta) if meta.file_type().is_symlink() => {
            Err(refuse("is a symbolic link; give a directory".to_string()))
        }
        Ok(meta) if !meta.is_dir() => Err(refuse("exists and is not a directory".to_string())),
        Ok(_) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            std::fs::create_dir_all(out).map_err(|e| refuse(format!("cannot create: {e}")))
        }
        Err(e) => Err(refuse(e.to_string())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_or_a_link_is_no_output_directory() {
        let base = std::env::temp_dir().join(format!("rins-plot-out-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir_all(&base).unwrap();
        let file = base.join("file");
        std::fs::write(&file, b"x").unwrap();
        assert!(prepare_output(&file).is_err());
        let link = base.join("link");
        std::os::unix::fs::symlink(&base, &link).unwrap();
        let e = prepare_output(&link).unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        let fresh = base.join("a/b");
        prepare_output(&fresh).unwrap();
        assert!(fresh.is_dir());
        prepare_output(&fresh).unwrap();
        std::fs::remove_dir_all(&base).unwrap();
    }

    #[test]
    fn the_embedded_font_draws_text() {
        font::register_font();
        let path = std::env::temp_dir().join(format!("rins-plot-font-{}.png", std::process::id()));
        let data = Extracted::default();
        draw::latency::draw(&path, &data).unwrap();
        assert!(std::fs::metadata(&path).unwrap().len() > 1000);
        std::fs::remove_file(&path).unwrap();
    }
}
