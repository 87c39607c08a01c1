//! The GNSS receiver's line as the operator sees it: the gnss service's counters in `rins status`
//! and in the run summary, and the warning for a line that carries bytes but nothing usable.

mod common;

use std::io::Write;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use common::{Isolated, TempFile, num, spawn_up_navigating, stop_up, up_json};
use serialport::{SerialPort, TTYPort};

/// A receiver's line that carries noise: bytes from a fixed pseudo-random sequence, about
/// 4 kB/s, until dropped. The slave side stays open so that the terminal outlives a reader.
struct NoisyLine {
    slave_name: String,
    stop: Arc<AtomicBool>,
    writer: Option<std::thread::JoinHandle<()>>,
    _slave: TTYPort,
}

impl NoisyLine {
    fn start() -> Self {
        let (mut master, slave) = TTYPort::pair().expect("cannot create a pseudo-terminal");
        let slave_name = slave.name().expect("the pseudo-terminal has a name");
        master
            .set_timeout(Duration::from_millis(100))
            .expect("timeout");
        let stop = Arc::new(AtomicBool::new(false));
        let flag = Arc::clone(&stop);
        let writer = std::thread::spawn(move || {
            let mut state = 0x2545_f491_4f6c_dd1d_u64;
            let mut chunk = [0u8; 80];
            while !flag.load(Ordering::Relaxed) {
                for b in &mut chunk {
                    state ^= state << 13;
                    state ^= state >> 7;
                    state ^= state << 17;
                    *b = (state >> 24) as u8;
                }
                // A full terminal (no reader yet) drops the chunk, as a real line would.
                let _ = master.write_all(&chunk);
                std::thread::sleep(Duration::from_millis(20));
            }
        });
        Self {
            slave_name,
            stop,
            writer: Some(writer),
            _slave: slave,
        }
    }
}

impl Drop for NoisyLine {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(w) = self.writer.take() {
            let _ = w.join();
        }
    }
}

/// A receiver line of noise: `rins status` shows the line's counters and the warning while the
/// pipeline runs, the gnss service logs it once, and the summary keeps the episode.
#[test]
fn a_line_of_noise_is_reported_as_silent_with_every_byte_counted() {
    let line = NoisyLine::start();
    let config = TempFile::new(
        "gnss-noise",
        "toml",
        &format!("[gnss]\nport = \"{}\"\n", line.slave_name),
    );
    let ipc = Isolated::new("gnss_line_noise");
    let up = spawn_up_navigating(&ipc, &["--gnss", "--config", config.path(), "--json"]);
    let report = ipc.status_until(Duration::from_secs(60), |r| r["gnss"]["silent"] == true);
    let gnss = &report["gnss"];
    assert!(
        gnss["warning"]
            .as_str()
            .is_some_and(|w| w.contains("no usable sentence or frame")),
        "{gnss}"
    );
    assert_eq!(
        (num(gnss, "sentences_used"), num(gnss, "ubx_frames_used")),
        (0.0, 0.0),
        "{gnss}"
    );
    assert_eq!(num(gnss, "published"), 0.0, "{gnss}");
    // Noise is counted as what it is: bytes outside any message, dropped sentence starts and
    // messages that failed their checksum, not as sentences.
    assert!(num(gnss, "bytes") > 4000.0, "{gnss}");
    assert!(
        num(gnss, "unframed_bytes") > 0.9 * num(gnss, "bytes"),
        "{gnss}"
    );
    let summary = stop_up(&ipc, up);
    let gnss = &summary["gnss"];
    assert!(num(gnss, "silent_episodes") >= 1.0, "{gnss}");
    assert!(
        ipc.up_stderr()
            .contains("the GNSS line carries bytes but no usable sentence or frame"),
        "the gnss service did not warn"
    );
}

/// The simulated receiver: every byte of its NMEA is used, none counted as bad, and every epoch
/// published, with a fix.
#[test]
fn the_simulated_receivers_line_is_used_whole() {
    let s = up_json("gnss_line_sim", &["--gnss", "--duration", "6"]);
    let gnss = &s["gnss"];
    assert!(num(gnss, "published") >= 15.0, "{gnss}");
    assert_eq!(num(gnss, "published"), num(gnss, "epochs"), "{gnss}");
    assert_eq!(num(gnss, "epochs_without_fix"), 0.0, "{gnss}");
    for bad in [
        "checksum_errors",
        "malformed",
        "resyncs",
        "unframed_bytes",
        "silent_episodes",
        "publish_failures",
    ] {
        assert_eq!(num(gnss, bad), 0.0, "{bad}: {gnss}");
    }
    // The simulator sends GGA, RMC, GST and VTG per epoch, each ended with CR LF.
    assert_eq!(
        num(gnss, "lines_crlf"),
        num(gnss, "sentences_used"),
        "{gnss}"
    );
    assert_eq!(num(gnss, "lines_lf"), 0.0, "{gnss}");
}
