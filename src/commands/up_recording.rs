//! The recording of `rins up`: its target checked before anything starts, the wait for its
//! recorder to subscribe, and what the run summary says of it.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use rins_runtime::shutdown::Shutdown;
use serde::Serialize;

use super::record_report::{FileCount, RecordReport};

/// What `rins up --record` reports of its recording in the run summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RecordingOutcome {
    /// The file.
    pub file: String,
    /// Samples written, all topics.
    pub samples_written: u64,
    /// Samples dropped because the writer could not keep up, or had stopped.
    pub samples_dropped: u64,
    /// Samples received that are not in the file.
    pub samples_not_recorded: u64,
    /// Size of the file, bytes (of every file, in a directory).
    pub file_bytes: u64,
    /// Why the recording failed (a write error, the recorder stopping); `null` when it did not.
    pub error: Option<String>,
    /// In a directory (`[record]`): each file written, in order.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<FileCount>,
    /// In a directory: the older recordings deleted to keep the total.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub files_deleted: Vec<String>,
}

impl RecordingOutcome {
    /// From how the recorder of `file` ended and what it printed on stdout (its `--json` report
    /// last): a recorder that failed, or ended without a report, is an error of the recording.
    pub fn from_recorder(file: &Path, status: std::process::ExitStatus, stdout: &[u8]) -> Self {
        let text = String::from_utf8_lossy(stdout);
        let report = text
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .and_then(|l| serde_json::from_str::<RecordReport>(l).ok());
        match report {
            Some(r) => Self {
                error: r.error.or_else(|| {
                    (!status.success()).then(|| format!("the recorder ended with {status}"))
                }),
                file: r.file,
                samples_written: r.samples_written,
                samples_dropped: r.samples_dropped,
                samples_not_recorded: r.samples_not_recorded,
                file_bytes: r.file_bytes,
                files: r.files,
                files_deleted: r.files_deleted,
            },
            None => Self::lost(
                file,
                format!("the recorder ended ({status}) without a report"),
            ),
        }
    }

    /// A recording of `file` that ended with `error` and nothing known of what it wrote.
    pub fn lost(file: &Path, error: String) -> Self {
        Self {
            file: file.display().to_string(),
            samples_written: 0,
            samples_dropped: 0,
            samples_not_recorded: 0,
            file_bytes: std::fs::metadata(file).map_or(0, |m| m.len()),
            error: Some(error),
            files: Vec::new(),
            files_deleted: Vec::new(),
        }
    }

    /// Why the run failed to record what was asked: an error, or samples that are not in the
    /// file. `None` when the file holds every sample received.
    pub fn failure(&self) -> Option<String> {
        match &self.error {
            Some(e) => Some(format!(
                "recording {} failed ({} samples not recorded): {e}",
                self.file, self.samples_not_recorded
            )),
            None if self.samples_not_recorded > 0 => Some(format!(
                "recording {}: {} samples not recorded (the writer could not keep up)",
                self.file, self.samples_not_recorded
            )),
            None => None,
        }
    }

    /// One line of the text summary.
    pub fn text(&self) -> String {
        let mut head = format!(
            "  recording {}: {} samples written, {} dropped, {} bytes",
            self.file, self.samples_written, self.samples_dropped, self.file_bytes
        );
        if !self.files.is_empty() {
            head.push_str(&format!(
                " in {} files, {} older deleted",
                self.files.len(),
                self.files_deleted.len()
            ));
        }
        match self.failure() {
            Some(why) => format!("{head}\n  FAILED: {why}\n"),
            None => format!("{head}\n"),
        }
    }
}

/// Checks, before anything starts, that a recording can be made at `path`: an existing target
/// must be a regular file (or a symbolic link, which is replaced, never followed), and its
/// directory must let a file be created there. Errors name the path and the system's reason.
pub fn check_target(path: &Path) -> Result<()> {
    use std::os::unix::fs::FileTypeExt;
    match std::fs::symlink_metadata(path) {
        Ok(meta) => {
            let t = meta.file_type();
            let kind = if t.is_dir() {
                Some("a directory")
            } else if t.is_fifo() {
                Some("a FIFO")
            } else if t.is_socket() {
                Some("a socket")
            } else if t.is_char_device() || t.is_block_device() {
                Some("a device")
            } else {
                None
            };
            if let Some(kind) = kind {
                bail!(
                    "--record {}: it is {kind}, not a regular file; refusing to record there",
                    path.display()
                );
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => bail!("--record {}: {e}", path.display()),
    }
    let Some(name) = path.file_name() else {
        bail!("--record {}: names no file", path.display());
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // A file of our own beside the target, so that an existing recording is not touched before
    // the run starts.
    let mut probe_name = std::ffi::OsString::from(".");
    probe_name.push(name);
    probe_name.push(format!(".{}.probe", std::process::id()));
    let probe = dir.join(probe_name);
    std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .open(&probe)
        .with_context(|| format!("--record {}: cannot create it", path.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// Waits until the recorder started for `file` has created `ready` (it then has subscribed to
/// every topic); `Ok(false)` when a stop was requested meanwhile. Fails as soon as the recorder
/// exits (its own error is on stderr already), or after `limit`.
pub fn wait_until_ready(
    child: &mut std::process::Child,
    ready: &Path,
    file: &Path,
    shutdown: &Shutdown,
    limit: Duration,
) -> Result<bool> {
    let deadline = Instant::now() + limit;
    while !ready.exists() {
        if shutdown.requested() {
            return Ok(false);
        }
        if let Some(status) = child.try_wait()? {
            bail!(
                "the recorder of {} ended ({status}) before it started",
                file.display()
            );
        }
        if Instant::now() >= deadline {
            bail!(
                "the recorder of {} did not start within {limit:?}",
                file.display()
            );
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    Ok(true)
}

/// The run summary of `rins up --json`, with its recording when there was one.
pub fn summary_json(
    summary: &rins_watchdog::summary::Summary,
    recording: Option<&RecordingOutcome>,
) -> Result<String> {
    #[derive(Serialize)]
    struct WithRecording<'a> {
        #[serde(flatten)]
        summary: &'a rins_watchdog::summary::Summary,
        #[serde(skip_serializing_if = "Option::is_none")]
        recording: Option<&'a RecordingOutcome>,
    }
    Ok(serde_json::to_string(&WithRecording {
        summary,
        recording,
    })?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;

    fn status(code: i32) -> std::process::ExitStatus {
        std::process::ExitStatus::from_raw(code << 8)
    }

    #[test]
    fn a_recorder_that_hit_a_full_disk_fails_the_run_and_says_why() {
        let report = RecordReport {
            file: "/tmp/x.mcap".into(),
            samples_written: 1_200,
            samples_dropped: 300,
            samples_received: 9_000,
            samples_not_recorded: 7_800,
            error: Some("/tmp/x.mcap: writing MCAP: No space left on device (os error 28)".into()),
            seconds: 3.0,
            file_bytes: 262_144,
            topics: Vec::new(),
            files: Vec::new(),
            files_deleted: Vec::new(),
        };
        let stdout = format!("{}\n", serde_json::to_string(&report).unwrap());
        let r =
            RecordingOutcome::from_recorder(Path::new("/tmp/x.mcap"), status(1), stdout.as_bytes());
        let why = r.failure().expect("a failure");
        assert!(why.contains("No space left on device"), "{why}");
        assert!(why.contains("7800 samples not recorded"), "{why}");
        assert!(r.text().contains("FAILED"), "{}", r.text());
        let json = summary_json(&rins_watchdog::summary::Summary::default(), Some(&r)).unwrap();
        let v: serde_json::Value = serde_json::from_str(&json).unwrap();
        assert_eq!(v["recording"]["samples_not_recorded"], 7_800);
        assert!(
            v["recording"]["error"]
                .as_str()
                .unwrap()
                .contains("os error 28")
        );
        // The summary's own fields are still at the top.
        assert_eq!(v["frames"], 0);
    }

    #[test]
    fn a_recorder_without_a_report_or_with_drops_fails_the_run() {
        let r = RecordingOutcome::from_recorder(Path::new("/tmp/none.mcap"), status(1), b"");
        assert!(r.failure().unwrap().contains("without a report"));
        let report = RecordReport {
            file: "/tmp/y.mcap".into(),
            samples_written: 10,
            samples_dropped: 2,
            samples_received: 12,
            samples_not_recorded: 2,
            error: None,
            seconds: 1.0,
            file_bytes: 100,
            topics: Vec::new(),
            files: Vec::new(),
            files_deleted: Vec::new(),
        };
        let stdout = serde_json::to_string(&report).unwrap();
        let r =
            RecordingOutcome::from_recorder(Path::new("/tmp/y.mcap"), status(0), stdout.as_bytes());
        assert!(r.failure().unwrap().contains("2 samples not recorded"));
        let whole = RecordReport {
            samples_dropped: 0,
            samples_not_recorded: 0,
            ..report
        };
        let stdout = serde_json::to_string(&whole).unwrap();
        let r =
            RecordingOutcome::from_recorder(Path::new("/tmp/y.mcap"), status(0), stdout.as_bytes());
        assert_eq!(r.failure(), None);
        let json = summary_json(&rins_watchdog::summary::Summary::default(), None).unwrap();
        assert!(!json.contains("recording"), "{json}");
    }

    #[test]
    fn a_target_that_is_no_regular_file_or_cannot_be_created_is_refused() {
        let dir = std::env::temp_dir().join(format!("rins-record-target-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let e = check_target(&dir).unwrap_err().to_string();
        assert!(
            e.contains("a directory") && e.contains(&dir.display().to_string()),
            "{e}"
        );
        let fifo = dir.join("fifo");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo(3) on a NUL-terminated path we own.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = check_target(&fifo).unwrap_err().to_string();
        assert!(e.contains("a FIFO"), "{e}");
        let e = format!("{:#}", check_target(Path::new("/dev/null")).unwrap_err());
        assert!(e.contains("a device"), "{e}");
        let e = format!(
            "{:#}",
            check_target(&dir.join("no/such/dir/x.mcap")).unwrap_err()
        );
        assert!(
            e.contains("no/such/dir/x.mcap") && e.contains("No such file"),
            "{e}"
        );
        // A path that can be created passes, and nothing is left behind.
        check_target(&dir.join("ok.mcap")).unwrap();
        let left: Vec<_> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("fifo")]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
