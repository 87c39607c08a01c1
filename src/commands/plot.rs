//! `rins plot FILE --out DIR`: the plots of a recording as PNG files.

use std::io::IsTerminal;
use std::path::Path;

use anyhow::Result;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;

#[derive(Serialize)]
struct Skipped<'a> {
    plot: &'a str,
    reason: &'a str,
}

#[derive(Serialize)]
struct Summary<'a> {
    written: Vec<String>,
    skipped: Vec<Skipped<'a>>,
}

pub fn run(file: &Path, out: &Path, json: bool) -> Result<()> {
    // A spinner on a terminal; plain lines otherwise, so that a log shows where a long file is.
    let spinner = std::io::stderr().is_terminal().then(|| {
        let bar = ProgressBar::new_spinner();
        if let Ok(style) = ProgressStyle::with_template("plot {spinner} {msg} {elapsed}") {
            bar.set_style(style);
        }
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        bar
    });
    let report = rins_plot::plot_recording(file, out, |step| match &spinner {
        Some(bar) => bar.set_message(step.to_string()),
        None => eprintln!("plot: {step}"),
    });
    if let Some(bar) = &spinner {
        bar.finish_and_clear();
    }
    let report = report?;
    if let Some(damage) = &report.damage {
        eprintln!("plot: {}: reading stopped early: {damage}", file.display());
    }
    if report.damaged_chunks > 0 {
        eprintln!(
            "plot: {}: {} damaged chunks skipped",
            file.display(),
            report.damaged_chunks
        );
    }
    if report.damaged_messages > 0 {
        eprintln!(
            "plot: {}: {} damaged messages skipped",
            file.display(),
            report.damaged_messages
        );
    }
    for path in &report.written {
        println!("wrote {}", path.display());
    }
    for (plot, reason) in &report.skipped {
        println!("skipped {plot}: {reason}");
    }
    if json {
        let summary = Summary {
            written: report
                .written
                .iter()
                .map(|p| p.display().to_string())
                .collect(),
            skipped: report
                .skipped
                .iter()
                .map(|(plot, reason)| Skipped { plot, reason })
                .collect(),
        };
        println!("{}", serde_json::to_string(&summary)?);
    }
    Ok(())
}
