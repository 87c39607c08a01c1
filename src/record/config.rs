//! `[record]`: whether `rins up` records from its start, where, and how much.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

/// The directory used when `dir` is not set and systemd gives no state directory.
pub const FALLBACK_DIR: &str = "recordings";
/// A file's size limit accepted, MB (10^6 bytes): from a minute at 1 kHz down to a test's seconds,
/// up to well within what the reader accepts of one file ([`rins_recording::MAX_RECORDING_BYTES`]).
pub const FILE_MB: std::ops::RangeInclusive<u64> = 1..=4096;
/// The largest total accepted, MB: 1 TB.
pub const MAX_TOTAL_MB: u64 = 1_000_000;

/// `[record]` of the configuration.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecordConfig {
    /// `rins up` records every topic from its start without `--record`.
    pub on_start: bool,
    /// Where: absent, `$STATE_DIRECTORY` when systemd sets it, else `./recordings`.
    pub dir: Option<String>,
    /// A file reaching this size, MB, is closed and the recording goes on in a new one.
    pub max_file_mb: u64,
    /// The most rins's own recordings in `dir` may take together, MB: before a new file is
    /// started, the oldest are deleted until it fits.
    pub max_total_mb: u64,
}

impl Default for RecordConfig {
    fn default() -> Self {
        Self {
            on_start: false,
            dir: None,
            max_file_mb: 256,
            max_total_mb: 2048,
        }
    }
}

impl RecordConfig {
    /// Checks every field; the error names it and its value.
    pub fn validate(&self) -> Result<(), String> {
        if let Some(dir) = &self.dir
            && dir.trim().is_empty()
        {
            return Err(format!("record.dir = {dir:?}: names no directory"));
        }
        check_limits(self.max_file_mb, self.max_total_mb, "record.")
    }

    /// The directory of the recordings: `dir`, else systemd's state directory (`state_directory`,
    /// the first of `$STATE_DIRECTORY`'s colon-separated paths), else [`FALLBACK_DIR`].
    pub fn directory(&self, state_directory: Option<&str>) -> PathBuf {
        if let Some(dir) = &self.dir {
            return PathBuf::from(dir);
        }
        state_directory
            .and_then(|s| s.split(':').find(|p| !p.is_empty()))
            .map_or_else(|| PathBuf::from(FALLBACK_DIR), PathBuf::from)
    }
}

/// Checks a file's and the total's limits, MB; the error names the field (after `prefix`:
/// `record.` for the configuration, `--` for the command line) and its value.
pub fn check_limits(max_file_mb: u64, max_total_mb: u64, prefix: &str) -> Result<(), String> {
    let dash = |name: &str| {
        if prefix == "--" {
            name.replace('_', "-")
        } else {
            name.to_string()
        }
    };
    let (file, total) = (dash("max_file_mb"), dash("max_total_mb"));
    if !FILE_MB.contains(&max_file_mb) {
        return Err(format!(
            "{prefix}{file} = {max_file_mb}: must be {}..={} MB",
            FILE_MB.start(),
            FILE_MB.end()
        ));
    }
    // Room for the file being written and the one before it, which may still be finishing.
    let least = 2 * max_file_mb;
    if !(least..=MAX_TOTAL_MB).contains(&max_total_mb) {
        return Err(format!(
            "{prefix}{total} = {max_total_mb}: must be {least}..={MAX_TOTAL_MB} MB (at least twice \
             {prefix}{file}: the file being written and the one before it)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_defaults_are_valid_and_bad_limits_name_field_and_value() {
        RecordConfig::default().validate().unwrap();
        let bad = |max_file_mb, max_total_mb| {
            RecordConfig {
                max_file_mb,
                max_total_mb,
                ..RecordConfig::default()
            }
            .validate()
            .unwrap_err()
        };
        assert!(
            bad(0, 2048).starts_with("record.max_file_mb = 0: must be 1..=4096"),
            "{}",
            bad(0, 2048)
        );
        assert!(bad(5000, 20_000).starts_with("record.max_file_mb = 5000"));
        let e = bad(256, 300);
        assert!(
            e.starts_with("record.max_total_mb = 300: must be 512..=1000000"),
            "{e}"
        );
        let e = RecordConfig {
            dir: Some(" ".into()),
            ..RecordConfig::default()
        }
        .validate()
        .unwrap_err();
        assert_eq!(e, "record.dir = \" \": names no directory");
        let e = check_limits(1, 1, "--").unwrap_err();
        assert!(e.starts_with("--max-total-mb = 1: must be 2..="), "{e}");
    }

    #[test]
    fn the_directory_is_the_configured_one_else_systemds_else_the_fallback() {
        let mut cfg = RecordConfig::default();
        assert_eq!(cfg.directory(None), PathBuf::from("recordings"));
        assert_eq!(
            cfg.directory(Some("/var/lib/rins:/var/lib/other")),
            PathBuf::from("/var/lib/rins")
        );
        assert_eq!(cfg.directory(Some("")), PathBuf::from("recordings"));
        cfg.dir = Some("/data/flights".into());
        assert_eq!(
            cfg.directory(Some("/var/lib/rins")),
            PathBuf::from("/data/flights")
        );
    }
}
