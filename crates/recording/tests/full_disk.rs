//! A recording whose disk fills up: the writer thread stops on the first failed write, the
//! senders learn it at once (so the recording is not carried on in vain), and the error that
//! comes back is the system's "no space left on device" under the file's name.
//!
//! The full disk is a real one: a 64 KiB tmpfs mounted for the test (it needs root, as the
//! continuous integration has; elsewhere the test says so and passes without running). A device
//! such as /dev/full does not do: it fails the recording's very first bytes, before any sample.

use std::io::ErrorKind;
use std::path::{Path, PathBuf};
use std::process::Command;

use ipc_types::{Altitude, names};
use rins_recording::{Dropped, RecordOptions, Recorder, join_writer, spawn_writer};

/// A tmpfs of `size` mounted on a fresh directory, unmounted and removed on drop.
struct TinyDisk {
    dir: PathBuf,
}

impl TinyDisk {
    fn mount(test: &str, size: &str) -> Option<Self> {
        let dir = std::env::temp_dir().join(format!("rins-tiny-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).ok()?;
        let mounted = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(&dir)
            .output()
            .is_ok_and(|o| o.status.success());
        if !mounted {
            let _ = std::fs::remove_dir(&dir);
            return None;
        }
        Some(Self { dir })
    }

    fn path(&self) -> &Path {
        &self.dir
    }
}

impl Drop for TinyDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.dir).status();
        let _ = std::fs::remove_dir(&self.dir);
    }
}

/// The first `std::io::Error` in `e`'s chain of sources.
fn io_cause<'a>(e: &'a (dyn std::error::Error + 'static)) -> Option<&'a std::io::Error> {
    let mut cur = Some(e);
    while let Some(err) = cur {
        if let Some(io) = err.downcast_ref::<std::io::Error>() {
            return Some(io);
        }
        cur = err.source();
    }
    None
}

/// Samples that compress badly, so that the disk fills within a few thousand.
fn noisy(i: u64) -> Altitude {
    let mut x = i.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        f64::from_bits((x >> 12) | 0x3FF0_0000_0000_0000)
    };
    Altitude {
        height_m: next(),
        vertical_speed_mps: next(),
        height_var: next(),
        ..Altitude::default()
    }
}

#[test]
fn a_full_disk_stops_the_writer_and_the_senders_are_told() {
    let Some(disk) = TinyDisk::mount("writer", "64k") else {
        eprintln!("skipped: cannot mount a tmpfs here (not root)");
        return;
    };
    let path = disk.path().join("full.mcap");
    let options = RecordOptions {
        chunk_size: 8 * 1024,
        ..RecordOptions::default()
    };
    let mut recorder = Recorder::create(&path, &options).unwrap();
    let alt = recorder.channel_for::<Altitude>(names::ALTITUDE).unwrap();
    let (sender, handle) = spawn_writer(recorder, 64).unwrap();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
    let mut sent = 0u64;
    while !sender.writer_failed() {
        assert!(
            std::time::Instant::now() < deadline,
            "the writer never reported the full disk ({sent} samples sent)"
        );
        if sender
            .try_send_payload(alt, sent, sent, &noisy(sent))
            .is_ok()
        {
            sent += 1;
        } else {
            std::thread::sleep(std::time::Duration::from_micros(100));
        }
    }
    // From now on nothing reaches the file, and every sample says why.
    assert_eq!(
        sender.try_send_payload(alt, 0, 0, &noisy(0)),
        Err(Dropped::WriterGone)
    );
    assert!(sender.dropped_total() >= 1);
    let written = sender.written_total();
    assert!(written > 0 && written < sent, "{written} of {sent}");
    drop(sender);
    let err = join_writer(handle).expect_err("a full disk is an error");
    let text = err.to_string();
    assert!(text.contains(&path.display().to_string()), "{text}");
    let io = io_cause(&err).unwrap_or_else(|| panic!("no I/O error under {err:?}"));
    assert_eq!(io.kind(), ErrorKind::StorageFull, "{err:?}");
}
