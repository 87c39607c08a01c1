//! Saving the resume point off the serial reader's thread. Writing the file — an unlink, a create,
//! a write and a rename — can block for hundreds of milliseconds when the file system is busy
//! (a journal commit behind a recording being written to the same disk), and the reader must not
//! stop reading for it: frames would pile up in the port's buffer, arrive as one burst and, past
//! the buffer's size, be lost. The reader offers the point once a second; a thread of its own
//! writes it, and a point offered while the previous one is still being written is skipped (the
//! next one is a second away and newer).

use std::path::PathBuf;
use std::thread::JoinHandle;

use crossbeam_channel::{Sender, bounded};
use rins_protocol::ResumePoint;

use crate::resume_file;

/// The thread that writes the resume points the reader offers.
pub struct ResumeSaver {
    path: PathBuf,
    points: Option<Sender<ResumePoint>>,
    thread: Option<JoinHandle<()>>,
}

impl ResumeSaver {
    /// Starts the writer for the file at `path`.
    pub fn start(path: PathBuf) -> std::io::Result<Self> {
        // One slot: the reader never waits, and never hands over more than one stale point.
        let (tx, rx) = bounded::<ResumePoint>(1);
        let file = path.clone();
        let thread = std::thread::Builder::new()
            .name("resume-saver".into())
            .spawn(move || {
                for point in rx {
                    save(&file, &point);
                }
            })?;
        Ok(Self {
            path,
            points: Some(tx),
            thread: Some(thread),
        })
    }

    /// Hands `point` to the writer without waiting (no allocation: the queue is a fixed slot); a
    /// writer still busy with the previous point makes this one skipped.
    pub fn offer(&self, point: ResumePoint) {
        if let Some(tx) = &self.points {
            // Full: the writer is busy and this point is skipped. Disconnected: the writer is
            // gone, and `finish` still saves the last point.
            let _ = tx.try_send(point);
        }
    }

    /// Stops the writer, then saves `last` here, after any point it was still writing: the file
    /// ends with the newest point.
    pub fn finish(mut self, last: ResumePoint) {
        self.stop();
        save(&self.path, &last);
    }

    fn stop(&mut self) {
        self.points = None;
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

impl Drop for ResumeSaver {
    fn drop(&mut self) {
        self.stop();
    }
}

fn save(path: &std::path::Path, point: &ResumePoint) {
    if let Err(e) = resume_file::save(path, point) {
        tracing::debug!(path = %path.display(), error = %e, "cannot save the resume point");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_ends_with_the_last_point() {
        let dir = std::env::temp_dir().join(format!("rins-resume-saver-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("resume");
        let saver = ResumeSaver::start(path.clone()).unwrap();
        let point = |t| ResumePoint {
            time_us: Some(t),
            ..ResumePoint::default()
        };
        for t in 1..100 {
            saver.offer(point(t));
        }
        saver.finish(point(1_000));
        match resume_file::load(&path) {
            resume_file::Loaded::Point(p) => assert_eq!(p.time_us, Some(1_000)),
            other => panic!("{other:?}"),
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
