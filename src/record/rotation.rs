//! The writer side of a recording: one MCAP file, or a run of them in a directory, each closed
//! once it reaches its size limit. The switch never stops the samples: a new file and its writer
//! thread are made first, the samples go to it from then on, and the old writer finishes its queue
//! and its file on its own thread, joined once it is done. Every file's counts are kept, so that
//! the report adds them up and says what any file failed to hold.

use std::path::{Path, PathBuf};
use std::thread::JoinHandle;
use std::time::SystemTime;

use anyhow::{Context, Result};
use rins_recording::{
    RecordError, RecordOptions, RecordSender, RecordSummary, Recorder, StructLayout, create_file,
    join_writer, spawn_writer,
};

use super::dir;
use super::naming::{self, Sequence};

/// Bytes in a MB of the size limits.
pub const MB: u64 = 1_000_000;
/// The largest chunk of a rotating recording: the writer's default.
const MAX_CHUNK: u64 = 1024 * 1024;

/// Where and how much a rotating recording writes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Limits {
    /// The directory of the files.
    pub dir: PathBuf,
    /// A file's size limit, bytes.
    pub max_file_bytes: u64,
    /// The limit of all of rins's own recordings in `dir`, bytes.
    pub max_total_bytes: u64,
}

impl Limits {
    /// The uncompressed size of a chunk: an eighth of a file at most, so that a file closed with
    /// its last chunk in memory ends within its limit (see [`Rotation::full`]).
    pub fn chunk_size(&self) -> u64 {
        (self.max_file_bytes / 8).clamp(4096, MAX_CHUNK)
    }
}

/// The files of one rotating recording: which run it is, which part comes next, what was deleted.
#[derive(Debug)]
pub struct Rotation {
    limits: Limits,
    uid: u32,
    run: u64,
    next_part: u64,
    /// Deleted to keep the total, oldest first.
    deleted: Vec<PathBuf>,
    /// Why something could not be deleted or a new file not be made.
    problems: Vec<String>,
}

impl Rotation {
    /// A new run in `limits.dir`, which must have passed [`dir::prepare`]: its number follows the
    /// highest of the recordings there.
    pub fn new(limits: Limits) -> Result<Self> {
        // SAFETY: geteuid(2) has no preconditions and cannot fail.
        let uid = unsafe { libc::geteuid() };
        let run = dir::next_run(&dir::own_recordings(&limits.dir, uid)?);
        Ok(Self {
            limits,
            uid,
            run,
            next_part: 1,
            deleted: Vec::new(),
            problems: Vec::new(),
        })
    }

    /// The options of every file: chunks sized to the limit.
    pub fn options(&self) -> RecordOptions {
        RecordOptions {
            chunk_size: self.limits.chunk_size(),
            ..RecordOptions::default()
        }
    }

    /// Deletes the oldest recordings until the next file fits the total, then creates it (never
    /// replacing anything). `in_use`: the files still being written, which are kept.
    pub fn create_next(&mut self, in_use: &[&Path]) -> Result<Recorder> {
        let own = dir::own_recordings(&self.limits.dir, self.uid)?;
        let busy: Vec<Sequence> = in_use
            .iter()
            .filter_map(|p| p.file_name()?.to_str().and_then(naming::parse))
            .collect();
        let chosen = dir::to_delete(
            &own,
            &busy,
            self.limits.max_file_bytes,
            self.limits.max_total_bytes,
        );
        let (deleted, failed) = dir::delete(&own, &chosen);
        for path in &deleted {
            eprintln!(
                "recording: deleted {} to keep the recordings within {} MB",
                path.display(),
                self.limits.max_total_bytes / MB
            );
        }
        self.deleted.extend(deleted);
        self.problems.extend(failed);
        let seq = Sequence {
            run: self.run,
            part: self.next_part,
        };
        let path = self
            .limits
            .dir
            .join(naming::file_name(seq, SystemTime::now()));
        let file = create_file(&path, false)
            .with_context(|| format!("cannot start recording {}", path.display()))?;
        self.next_part += 1;
        Ok(Recorder::on_file(file, path, &self.options())?)
    }

    /// Whether a file of `bytes` on disk is to be closed: its last chunk, still in memory, and
    /// the summary written at its end must fit within the limit. A chunk is at most an eighth of
    /// it, and written compressed.
    pub fn full(&self, bytes: u64) -> bool {
        bytes.saturating_add(2 * self.limits.chunk_size()) >= self.limits.max_file_bytes
    }
}

/// What one file of a recording holds, or why it failed.
#[derive(Debug)]
pub struct FileOutcome {
    /// The file.
    pub path: PathBuf,
    /// Samples written to it (when it failed: those known written before).
    pub written: u64,
    /// Samples dropped while it was being written.
    pub dropped: u64,
    /// Its size, bytes.
    pub file_bytes: u64,
    /// Per topic, in registration order: written and dropped (empty when it failed).
    pub topics: Vec<(String, u64, u64)>,
    /// Why it failed; the file is incomplete.
    pub error: Option<RecordError>,
}

impl FileOutcome {
    fn from_summary(s: &RecordSummary) -> Self {
        Self {
            path: s.path.clone(),
            written: s.samples_written,
            dropped: s.samples_dropped,
            file_bytes: s.file_bytes,
            topics: s
                .topics
                .iter()
                .map(|t| (t.topic.clone(), t.written, t.dropped))
                .collect(),
            error: None,
        }
    }

    fn failed(path: &Path, error: RecordError, (written, dropped): (u64, u64)) -> Self {
        Self {
            path: path.to_path_buf(),
            written,
            dropped,
            file_bytes: std::fs::symlink_metadata(path).map_or(0, |m| m.len()),
            topics: Vec::new(),
            error: Some(error),
        }
    }
}

type Writer = JoinHandle<Result<RecordSummary, RecordError>>;

/// The file being written: its queue and its writer thread (none once it failed).
struct Current {
    path: PathBuf,
    sender: RecordSender,
    writer: Option<Writer>,
}

/// A file closed for rotation whose writer is finishing: the counts known when it was closed
/// (the drops are final then; the writes a lower bound).
struct Closing {
    path: PathBuf,
    writer: Writer,
    counts: (u64, u64),
}

/// Where the samples of a recording go: [`RecordSink::sender`] of the file being written.
pub struct RecordSink {
    channels: Vec<(String, &'static StructLayout)>,
    queue: usize,
    rotation: Option<Rotation>,
    current: Current,
    closing: Vec<Closing>,
    done: Vec<FileOutcome>,
    /// Set once the file being written failed: nothing more is recorded.
    stopped: bool,
}

impl RecordSink {
    /// Starts writing `recorder` (its channels registered) behind a queue of `queue` samples;
    /// with `rotation`, a new file follows each time one is full ([`RecordSink::rotate_if_full`]).
    pub fn start(recorder: Recorder, rotation: Option<Rotation>, queue: usize) -> Result<Self> {
        let channels = (0..=u16::MAX)
            .map_while(|i| recorder.channel_info(rins_recording::ChannelId(i)))
            .map(|(topic, layout)| (topic.to_string(), layout))
            .collect();
        let path = recorder.path().to_path_buf();
        let (sender, writer) = spawn_writer(recorder, queue).context("cannot start the writer")?;
        Ok(Self {
            channels,
            queue,
            rotation,
            current: Current {
                path,
                sender,
                writer: Some(writer),
            },
            closing: Vec::new(),
            done: Vec::new(),
            stopped: false,
        })
    }

    /// The queue of the file being written.
    pub fn sender(&self) -> &RecordSender {
        &self.current.sender
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.current.path
    }

    /// Samples written so far (the file being written and those before it).
    pub fn written_total(&self) -> u64 {
        let before: u64 = self.done.iter().map(|f| f.written).sum::<u64>()
            + self.closing.iter().map(|c| c.counts.0).sum::<u64>();
        before + self.current.sender.written_total()
    }

    /// Samples dropped so far.
    pub fn dropped_total(&self) -> u64 {
        let before: u64 = self.done.iter().map(|f| f.dropped).sum::<u64>()
            + self.closing.iter().map(|c| c.counts.1).sum::<u64>();
        before + self.current.sender.dropped_total()
    }

    /// When the writer of the file being written has just failed: why. From then on nothing more
    /// is recorded (the samples sent are counted as dropped).
    pub fn newly_failed(&mut self) -> Option<String> {
        if self.stopped || !self.current.sender.writer_failed() {
            return None;
        }
        self.stopped = true;
        let writer = self.current.writer.take()?;
        let counts = (
            self.current.sender.written_total(),
            self.current.sender.dropped_total(),
        );
        let error = match join_writer(writer) {
            Err(e) => e,
            // Flagged, so it failed; a summary here would contradict the flag.
            Ok(_) => RecordError::WriterPanicked,
        };
        let why = error_text(&error);
        self.done
            .push(FileOutcome::failed(&self.current.path, error, counts));
        Some(why)
    }

    /// Moves to a new file when the one being written is full (a rotating recording that has not
    /// failed); then returns the new file. A new file that cannot be made leaves the recording in
    /// the old one, beyond its limit, and stops the rotation; the report says why.
    pub fn rotate_if_full(&mut self) -> Option<PathBuf> {
        let rotation = self.rotation.as_mut()?;
        if self.stopped {
            return None;
        }
        let bytes = std::fs::symlink_metadata(&self.current.path).map_or(0, |m| m.len());
        if !rotation.full(bytes) {
            return None;
        }
        let mut in_use: Vec<&Path> = self.closing.iter().map(|c| c.path.as_path()).collect();
        in_use.push(&self.current.path);
        let next = rotation.create_next(&in_use).and_then(|mut recorder| {
            for (topic, layout) in &self.channels {
                recorder.channel(topic, layout)?;
            }
            let path = recorder.path().to_path_buf();
            let (sender, writer) =
                spawn_writer(recorder, self.queue).context("cannot start the writer")?;
            Ok(Current {
                path,
                sender,
                writer: Some(writer),
            })
        });
        let next = match next {
            Ok(n) => n,
            Err(e) => {
                let why = format!(
                    "{:#}; recording on in {} beyond its limit",
                    e,
                    self.current.path.display()
                );
                eprintln!("recording: {why}");
                rotation.problems.push(why);
                self.rotation = None;
                return None;
            }
        };
        let old = std::mem::replace(&mut self.current, next);
        let counts = (old.sender.written_total(), old.sender.dropped_total());
        // The last sender of the old file: dropping it lets its writer finish the file.
        drop(old.sender);
        if let Some(writer) = old.writer {
            self.closing.push(Closing {
                path: old.path,
                writer,
                counts,
            });
        }
        Some(self.current.path.clone())
    }

    /// Collects the files whose writers have finished, without waiting for the others.
    pub fn collect_closed(&mut self) {
        let mut i = 0;
        while i < self.closing.len() {
            if self.closing[i].writer.is_finished() {
                let c = self.closing.swap_remove(i);
                self.done.push(join_closing(c));
            } else {
                i += 1;
            }
        }
    }

    /// Finishes the file being written and waits for every writer: each file's outcome in the
    /// order written, the recordings deleted, and the problems of the rotation.
    pub fn finish(mut self) -> (Vec<FileOutcome>, Vec<PathBuf>, Vec<String>) {
        let Current {
            path,
            sender,
            writer,
        } = self.current;
        let counts = (sender.written_total(), sender.dropped_total());
        drop(sender);
        if let Some(writer) = writer {
            self.done.push(match join_writer(writer) {
                Ok(summary) => FileOutcome::from_summary(&summary),
                Err(e) => FileOutcome::failed(&path, e, counts),
            });
        } else if !self.done.iter().any(|f| f.path == path) {
            self.done.push(FileOutcome::failed(
                &path,
                RecordError::WriterPanicked,
                counts,
            ));
        } else if let Some(f) = self.done.iter_mut().find(|f| f.path == path) {
            // Failed earlier: what was sent since is dropped too.
            f.dropped = counts.1;
        }
        for c in self.closing.drain(..) {
            self.done.push(join_closing(c));
        }
        self.done.sort_by(|a, b| a.path.cmp(&b.path));
        let (deleted, problems) = self
            .rotation
            .map(|r| (r.deleted, r.problems))
            .unwrap_or_default();
        (self.done, deleted, problems)
    }
}

fn join_closing(c: Closing) -> FileOutcome {
    match join_writer(c.writer) {
        Ok(summary) => FileOutcome::from_summary(&summary),
        Err(e) => FileOutcome::failed(&c.path, e, c.counts),
    }
}

/// `e` and the causes under it, each once: the MCAP writer's message repeats its source's.
pub fn error_text(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let more = c.to_string();
        if !text.contains(&more) {
            text = format!("{text}: {more}");
        }
        cause = c.source();
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::RawImu;
    use rins_recording::ChannelId;

    /// Sends `n` raw IMU samples of noise-like counts through `sink`, rotating as the recorder's loop
    /// does, at the pace of the writer (as at 1 kHz, where its queue is all but empty); each
    /// sample carries its index as its log time, so that the files can be checked for every one.
    fn send(sink: &mut RecordSink, channel: ChannelId, n: u64) {
        let mut imu = RawImu::default();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut sent_to_current = 0;
        for i in 0..n {
            for c in imu.gyro_counts.iter_mut().chain(&mut imu.accel_counts) {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                *c = (state >> 48) as i16;
            }
            sink.sender()
                .try_send_payload(channel, i, i, &imu)
                .expect("queued");
            sent_to_current += 1;
            if i % 50 == 49 {
                while sink.sender().written_total() < sent_to_current {
                    std::thread::sleep(std::time::Duration::from_micros(200));
                }
                if sink.rotate_if_full().is_some() {
                    sent_to_current = 0;
                }
                sink.collect_closed();
            }
        }
    }

    #[test]
    fn a_rotating_recording_spreads_every_sample_over_files_within_the_limit() {
        let dir = std::env::temp_dir().join(format!("rins-rotation-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir::prepare(&dir, "test").unwrap();
        let limits = Limits {
            dir: dir.clone(),
            max_file_bytes: 200_000,
            max_total_bytes: 100_000_000,
        };
        let mut rotation = Rotation::new(limits).unwrap();
        let mut recorder = rotation.create_next(&[]).unwrap();
        let channel = recorder.channel_for::<RawImu>("rt/raw_imu").unwrap();
        const N: u64 = 40_000;
        let mut sink = RecordSink::start(recorder, Some(rotation), 4096).unwrap();
        send(&mut sink, channel, N);
        let (files, deleted, problems) = sink.finish();
        assert!(deleted.is_empty() && problems.is_empty(), "{problems:?}");
        assert!(files.len() >= 3, "{} files", files.len());
        let mut times = Vec::new();
        for f in &files {
            assert!(f.error.is_none(), "{f:?}");
            assert!(
                f.file_bytes <= 200_000,
                "{}: {} bytes",
                f.path.display(),
                f.file_bytes
            );
            let rec = rins_recording::read_file(&f.path).unwrap();
            assert_eq!(rec.messages.len() as u64, f.written);
            times.extend(rec.messages.iter().map(|m| m.log_time_ns));
        }
        // Every sample once, in order across the files: none lost or doubled at a switch.
        assert_eq!(times, (0..N).collect::<Vec<_>>());
        assert_eq!(files.iter().map(|f| f.written).sum::<u64>(), N);
        assert_eq!(files.iter().map(|f| f.dropped).sum::<u64>(), 0);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
