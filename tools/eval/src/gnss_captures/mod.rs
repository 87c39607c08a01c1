//! How much of what real GNSS receivers emit the product's decoder turns into fixes.
//!
//! Each capture (`NAME.log`: `#` comment lines, then a receiver's raw NMEA/UBX bytes) is played
//! through [`rins_gnss_protocol::decode::GnssDecoder`] as a 9600-baud serial line delivers it
//! ([`replay`]); the fixes it publishes are matched by the receiver's time to the fix epochs
//! gpsd decoded from the same bytes (`NAME.log.chk`, [`reference`]) and their positions compared
//! ([`score`]); [`report`] adds them up per capture, per protocol and in total. [`live`] scores the
//! fixes a running `gnss` service published from the same bytes the same way. Beside gpsd's
//! decode, each fix is also compared with the capture's own position messages of its receiver
//! time ([`own_positions`], read without the product's parsers; [`score::score_own`]).

pub mod live;
pub mod own_positions;
pub mod reference;
pub mod replay;
pub mod report;
pub mod score;

use std::path::Path;

use anyhow::{Context, Result};
use ipc_types::GnssFix;
use rins_gnss_protocol::decode::GnssDecoderStats;
use serde::Serialize;

use replay::{ProtocolGroup, ProtocolsSeen};
pub use report::{CapturesReport, to_table};
use score::{OwnScore, Score};

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
    /// gpsd's fixes that the receiver's own UBX output calls time-only: not reference epochs
    /// (see [`reference`]).
    pub reference_time_only_epochs: usize,
    /// Published fixes against the reference.
    pub score: Score,
    /// Published fixes against the capture's own position messages of the same receiver time.
    pub own: OwnScore,
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
    let (fixes, stats) = replay::decode(replay::receiver_bytes(log));
    score_capture(name, log, chk, &fixes, stats)
}

/// Scores `fixes`, published from capture `log` by a decoder that was fed its receiver bytes and
/// ended with the counters `decoder`, against gpsd's decode `chk`: the one scoring of both the
/// in-process decoder and the running service.
pub fn score_capture(
    name: &str,
    log: &[u8],
    chk: &str,
    fixes: &[GnssFix],
    decoder: GnssDecoderStats,
) -> CaptureResult {
    let bytes = replay::receiver_bytes(log);
    let reference = reference::reference_epochs(chk, bytes);
    let seen = replay::protocols_seen(bytes);
    CaptureResult {
        name: name.to_string(),
        protocols: seen.group(),
        seen,
        reference_fixes_without_time: reference.fixes_without_time,
        reference_unreadable_lines: reference.unreadable_lines,
        reference_time_only_epochs: reference.time_only_epochs,
        score: score::score(&reference.epochs, fixes),
        own: score::score_own(&own_positions::own_positions(bytes), fixes),
        decoder,
    }
}

/// Evaluates every `*.log` in `dir` that has its `*.log.chk` beside it, in name order; a capture
/// that cannot be read is listed in the report's failures and the rest go on.
/// `progress(done, total)` is called after each.
pub fn evaluate(dir: &Path, progress: &mut dyn FnMut(usize, usize)) -> Result<CapturesReport> {
    let names = capture_names(dir)?;
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

/// The file names of the captures (`*.log`) in `dir`, in name order; an error when there is none.
pub fn capture_names(dir: &Path) -> Result<Vec<String>> {
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
    Ok(names)
}

/// Capture `name` of `dir` and gpsd's decode of it (`NAME.chk` beside it).
pub fn read_capture(dir: &Path, name: &str) -> Result<(Vec<u8>, String)> {
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
