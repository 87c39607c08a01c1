//! How much of what real GNSS receivers emit the product's decoder turns into fixes.
//!
//! Each capture (`NAME.log`: `#` comment lines, then a receiver's raw NMEA/UBX bytes) is played
//! through [`rins_gnss_protocol::decode::GnssDecoder`] as a 9600-baud serial line delivers it
//! ([`replay`]); the fixes it publishes are matched by the receiver's time to the fix epochs
//! gpsd decoded from the same bytes (`NAME.log.chk`, [`reference`]) and their positions compared
//! ([`score`]); [`report`] adds them up per capture, per protocol and in total.

pub mod reference;
pub mod replay;
pub mod report;
pub mod score;

use std::path::Path;

use anyhow::{Context, Result};
use rins_gnss_protocol::decode::GnssDecoderStats;
use serde::Serialize;

use replay::{ProtocolGroup, ProtocolsSeen};
pub use report::{CapturesReport, to_table};
use score::Score;

/// One capture's result.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CaptureResult {
    /// File name of the capture.
    pub name: String,
    /// The protocols its bytes carry.
    pub protocols: ProtocolGroup,
    /// What they carry, counted.
    pub seen: ProtocolsSeen,
    /// gpsd's fixes without a time: not matchable, not counted as reference epochs.
    pub reference_fixes_without_time: usize,
    /// Lines of the reference that look like JSON but do not parse.
    pub reference_unreadable_lines: usize,
    /// Published fixes against the reference.
    pub score: Score,
    /// The decoder's counters at the end of the capture, every one of them.
    pub decoder: GnssDecoderStats,
}

/// A capture that could not be evaluated, and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Failure {
    /// File name.
    pub name: String,
    /// What went wrong.
    pub reason: String,
}

/// Evaluates one capture: `log` is the capture file's bytes, `chk` gpsd's decode of it.
pub fn evaluate_capture(name: &str, log: &[u8], chk: &str) -> CaptureResult {
    let bytes = replay::receiver_bytes(log);
    let reference = reference::reference_epochs(chk);
    let (fixes, stats) = replay::decode(bytes);
    let seen = replay::protocols_seen(bytes);
    CaptureResult {
        name: name.to_string(),
        protocols: seen.group(),
        seen,
        reference_fixes_without_time: reference.fixes_without_time,
        reference_unreadable_lines: reference.unreadable_lines,
        score: score::score(&reference.epochs, &fixes),
        decoder: stats,
    }
}

/// Evaluates every `*.log` in `dir` that has its `*.log.chk` beside it, in name order; a capture
/// that cannot be read is listed in the report's failures and the rest go on.
/// `progress(done, total)` is called after each.
pub fn evaluate(dir: &Path, progress: &mut dyn FnMut(usize, usize)) -> Result<CapturesReport> {
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list the capture directory {}", dir.display()))?;
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".log"))
        .collect();
    names.sort();
    if names.is_empty() {
        anyhow::bail!("no capture (*.log) in {}", dir.display());
    }
    let mut captures = Vec::with_capacity(names.len());
    let mut failures = Vec::new();
    for (i, name) in names.iter().enumerate() {
        match read_capture(dir, name) {
            Ok((log, chk)) => captures.push(evaluate_capture(name, &log, &chk)),
            Err(e) => failures.push(Failure {
                name: name.clone(),
                reason: format!("{e:#}"),
            }),
        }
        progress(i + 1, names.len());
    }
    Ok(report::build(captures, failures))
}

fn read_capture(dir: &Path, name: &str) -> Result<(Vec<u8>, String)> {
    let log_path = dir.join(name);
    let chk_path = dir.join(format!("{name}.chk"));
    let log =
        std::fs::read(&log_path).with_context(|| format!("cannot read {}", log_path.display()))?;
    let chk = std::fs::read(&chk_path)
        .with_context(|| format!("cannot read the reference {}", chk_path.display()))?;
    // gpsd writes JSON (UTF-8) and echoes the input lines, which may hold any byte: the echoed
    // lines are not used, so a lossy reading loses nothing that counts.
    Ok((log, String::from_utf8_lossy(&chk).into_owned()))
}
