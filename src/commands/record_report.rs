//! What `rins record --json` prints last: the samples received, written and dropped, per topic
//! and per file, and why a recording failed.

use std::path::{Path, PathBuf};

use rins::record::rotation::{FileOutcome, error_text};
use serde::{Deserialize, Serialize};

/// What `rins record --json` prints last.
#[derive(Debug, Serialize, Deserialize)]
pub struct RecordReport {
    /// The file written; with `--dir`, the directory.
    pub file: String,
    /// Samples written, all topics.
    pub samples_written: u64,
    /// Samples dropped because the writer could not keep up.
    pub samples_dropped: u64,
    /// Samples received from the topics.
    pub samples_received: u64,
    /// Samples received that are not in the file: dropped, or queued when the writer failed.
    #[serde(default)]
    pub samples_not_recorded: u64,
    /// Why the recording failed (the file is incomplete); absent when it did not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// How long the recording ran, s.
    pub seconds: f64,
    /// Size of the file, bytes; with `--dir`, of every file written.
    pub file_bytes: u64,
    /// Per topic: written and dropped.
    pub topics: Vec<TopicCount>,
    /// With `--dir`: each file written, in order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<FileCount>,
    /// With `--dir`: the older recordings deleted to keep the total.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files_deleted: Vec<String>,
}

/// One file of a recording made with `--dir`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FileCount {
    /// The file.
    pub file: String,
    /// Samples written to it.
    pub samples_written: u64,
    /// Its size, bytes.
    pub file_bytes: u64,
}

/// One topic of [`RecordReport`].
#[derive(Debug, Serialize, Deserialize)]
pub struct TopicCount {
    /// The topic.
    pub topic: String,
    /// Samples written.
    pub written: u64,
    /// Samples dropped.
    pub dropped: u64,
}

impl RecordReport {
    /// The report of the files written to `path` (a directory when `rotating`), `received`
    /// samples taken off the topics in `seconds`.
    pub(super) fn new(
        path: &Path,
        rotating: bool,
        (files, deleted, problems): (Vec<FileOutcome>, Vec<PathBuf>, Vec<String>),
        received: u64,
        seconds: f64,
    ) -> Self {
        let written: u64 = files.iter().map(|f| f.written).sum();
        let mut topics: Vec<TopicCount> = Vec::new();
        for (topic, w, d) in files.iter().flat_map(|f| f.topics.iter()) {
            match topics.iter_mut().find(|t| t.topic == *topic) {
                Some(t) => {
                    t.written += w;
                    t.dropped += d;
                }
                None => topics.push(TopicCount {
                    topic: topic.clone(),
                    written: *w,
                    dropped: *d,
                }),
            }
        }
        // The first failure of a file, then what kept the rotation from its limits.
        let error = files
            .iter()
            .find_map(|f| f.error.as_ref().map(|e| error_text(e)))
            .or_else(|| (!problems.is_empty()).then(|| problems.join("; ")));
        Self {
            file: path.display().to_string(),
            samples_written: written,
            samples_dropped: files.iter().map(|f| f.dropped).sum(),
            samples_received: received,
            samples_not_recorded: received.saturating_sub(written),
            error,
            seconds,
            file_bytes: files.iter().map(|f| f.file_bytes).sum(),
            topics,
            files: if rotating {
                files
                    .iter()
                    .map(|f| FileCount {
                        file: f.path.display().to_string(),
                        samples_written: f.written,
                        file_bytes: f.file_bytes,
                    })
                    .collect()
            } else {
                Vec::new()
            },
            files_deleted: deleted.iter().map(|p| p.display().to_string()).collect(),
        }
    }
}
