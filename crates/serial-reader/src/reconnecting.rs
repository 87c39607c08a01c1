//! The one loop every serial reader runs: open the device, read it until it is lost, wait with
//! backoff, open it again, until a stop is requested. The loop owns the decisions (when to retry,
//! how long to wait, what counts as lost) and the process's share of them: the stop flag, the
//! reconnect count and the heartbeat of its [`ServiceLoop`], sent after every read and through
//! every wait, so that a process waiting for its device is never taken for hung. The reader's
//! [`LineEvents`] say what each event means to it (logging, decoding, its own counters).

use std::io::Read;
use std::time::Duration;

use anyhow::Result;
use ipc_types::Health;
use rins_runtime::clock::monotonic_ns;
use rins_runtime::service_loop::ServiceLoop;
use rins_runtime::shutdown::Shutdown;

use crate::line_config::SerialLineConfig;
use crate::port;
use crate::presence::{Opened, Presence, Retry};
use crate::wait::wait_for_retry;

/// What a reader does at each event of its line. Called from the loop's thread; `bytes` and
/// `after_read` run once per read and must not allocate, log or lock on their normal path.
pub trait LineEvents {
    /// An attempt to open the device failed with `error`; the loop waits `retry.delay` next.
    fn open_failed(&mut self, error: &anyhow::Error, retry: &Retry, presence: &Presence);
    /// The device opened: the first time, or back after an absence (already counted in
    /// [`Health::reconnects`]).
    fn opened(&mut self, opened: Opened, presence: &Presence);
    /// A read returned `bytes` (never empty).
    fn bytes(&mut self, bytes: &[u8], counters: &mut Health);
    /// After every read that did not lose the device, bytes or timeout, before the heartbeat:
    /// the place for statistics.
    fn after_read(&mut self, counters: &mut Health);
    /// The open device was lost with `error`; the loop waits `delay` before reopening it.
    fn lost(&mut self, error: &std::io::Error, delay: Duration, presence: &Presence);
}

/// What the loop needs of the process around it: [`ServiceLoop`] in a service.
trait Process {
    fn shutdown(&self) -> &Shutdown;
    fn counters(&mut self) -> &mut Health;
    fn beat(&mut self) -> Result<()>;
}

impl Process for ServiceLoop {
    fn shutdown(&self) -> &Shutdown {
        ServiceLoop::shutdown(self)
    }
    fn counters(&mut self) -> &mut Health {
        &mut self.counters
    }
    fn beat(&mut self) -> Result<()> {
        Ok(ServiceLoop::beat(self)?)
    }
}

/// Reads the device at `path` with the settings of `line` into `events` until the stop of
/// `service` is requested, reading at most `buf.len()` bytes at a time. A missing or lost device is
/// retried with the line's backoff, never given up on. Returns the final counters, or the first
/// error of the heartbeat.
pub fn read_reconnecting(
    path: &str,
    line: &SerialLineConfig,
    mut service: ServiceLoop,
    buf: &mut [u8],
    events: &mut impl LineEvents,
) -> Result<Health> {
    reconnect_loop(path, line, &mut service, buf, events)?;
    Ok(service.counters)
}

fn reconnect_loop(
    path: &str,
    line: &SerialLineConfig,
    process: &mut impl Process,
    buf: &mut [u8],
    events: &mut impl LineEvents,
) -> Result<()> {
    // The waits poll the flag while the process beats; a clone shares it.
    let shutdown = process.shutdown().clone();
    let mut presence = Presence::new(line.backoff());
    while !shutdown.requested() {
        let port = match port::open(path, line.baud, line.read_timeout()) {
            Ok(port) => port,
            Err(e) => {
                let retry = presence.open_failed(monotonic_ns());
                events.open_failed(&e, &retry, &presence);
                wait_for_retry(retry.delay, &shutdown, || process.beat())?;
                continue;
            }
        };
        let opened = presence.opened(monotonic_ns());
        if let Opened::Reconnected { .. } = opened {
            process.counters().reconnects = presence.reconnects();
        }
        events.opened(opened, &presence);
        let lost = read_until_lost(port, &shutdown, buf, &mut presence, process, events)?;
        if let Some(e) = lost
            && !shutdown.requested()
        {
            let delay = presence.lost(monotonic_ns());
            events.lost(&e, delay, &presence);
            wait_for_retry(delay, &shutdown, || process.beat())?;
        }
    }
    Ok(())
}

/// Reads `port` until it fails (the error) or a stop is requested (`None`). Allocation-free and
/// lock-free per read.
fn read_until_lost(
    mut port: impl Read,
    shutdown: &Shutdown,
    buf: &mut [u8],
    presence: &mut Presence,
    process: &mut impl Process,
    events: &mut impl LineEvents,
) -> Result<Option<std::io::Error>> {
    while !shutdown.requested() {
        match port.read(buf) {
            // End of file: the other end hung up.
            Ok(0) => return Ok(Some(std::io::ErrorKind::UnexpectedEof.into())),
            Ok(n) => {
                presence.data_arrived();
                events.bytes(&buf[..n], process.counters());
            }
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                ) => {}
            Err(e) => return Ok(Some(e)),
        }
        events.after_read(process.counters());
        process.beat()?;
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::ErrorKind;

    /// A port that plays back a script of reads.
    struct Script(std::vec::IntoIter<std::io::Result<Vec<u8>>>);

    impl Read for Script {
        fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
            match self.0.next() {
                Some(Ok(bytes)) => {
                    buf[..bytes.len()].copy_from_slice(&bytes);
                    Ok(bytes.len())
                }
                Some(Err(e)) => Err(e),
                None => Ok(0),
            }
        }
    }

    /// The process around the loop, without IPC: its beats are counted.
    struct Fake {
        shutdown: Shutdown,
        counters: Health,
        beats: usize,
    }

    impl Fake {
        fn new(shutdown: Shutdown) -> Self {
            Self {
                shutdown,
                counters: Health::default(),
                beats: 0,
            }
        }
    }

    impl Process for Fake {
        fn shutdown(&self) -> &Shutdown {
            &self.shutdown
        }
        fn counters(&mut self) -> &mut Health {
            &mut self.counters
        }
        fn beat(&mut self) -> Result<()> {
            self.beats += 1;
            Ok(())
        }
    }

    #[derive(Default)]
    struct Log {
        bytes: Vec<u8>,
        after_reads: usize,
    }

    impl LineEvents for Log {
        fn open_failed(&mut self, _: &anyhow::Error, _: &Retry, _: &Presence) {}
        fn opened(&mut self, _: Opened, _: &Presence) {}
        fn bytes(&mut self, bytes: &[u8], counters: &mut Health) {
            self.bytes.extend_from_slice(bytes);
            counters.bytes_received += bytes.len() as u64;
        }
        fn after_read(&mut self, _: &mut Health) {
            self.after_reads += 1;
        }
        fn lost(&mut self, _: &std::io::Error, _: Duration, _: &Presence) {}
    }

    fn presence() -> Presence {
        Presence::new(crate::backoff::Backoff::new(
            Duration::from_millis(10),
            Duration::from_millis(1000),
        ))
    }

    #[test]
    fn timeouts_are_no_loss_and_a_hang_up_or_error_is() {
        let script = Script(
            vec![
                Ok(b"ab".to_vec()),
                Err(ErrorKind::TimedOut.into()),
                Err(ErrorKind::Interrupted.into()),
                Ok(b"c".to_vec()),
            ]
            .into_iter(),
        );
        let mut log = Log::default();
        let mut p = presence();
        p.opened(0);
        let shutdown = Shutdown::manual();
        let mut process = Fake::new(shutdown.clone());
        let lost = read_until_lost(
            script,
            &shutdown,
            &mut [0; 8],
            &mut p,
            &mut process,
            &mut log,
        )
        .unwrap()
        .expect("the end of the script is a hang-up");
        assert_eq!(lost.kind(), ErrorKind::UnexpectedEof);
        // Four reads before the hang-up, each followed by `after_read` and a heartbeat; the
        // hang-up is not. The reader's counters are the process's.
        assert_eq!((log.bytes.as_slice(), log.after_reads), (&b"abc"[..], 4));
        assert_eq!((process.beats, process.counters.bytes_received), (4, 3));
        // The device delivered data: its loss starts the shortest backoff.
        assert_eq!(p.lost(1), Duration::from_millis(10));

        let script = Script(vec![Err(ErrorKind::BrokenPipe.into())].into_iter());
        let lost = read_until_lost(
            script,
            &shutdown,
            &mut [0; 8],
            &mut p,
            &mut process,
            &mut log,
        )
        .unwrap()
        .expect("an I/O error is a loss");
        assert_eq!(lost.kind(), ErrorKind::BrokenPipe);
    }

    fn line() -> SerialLineConfig {
        SerialLineConfig {
            port: None,
            baud: 9600,
            read_timeout_ms: 50,
            reconnect_initial_ms: 10,
            reconnect_max_ms: 1000,
        }
    }

    #[test]
    fn a_stop_ends_the_loops_without_a_loss() {
        let shutdown = Shutdown::manual();
        shutdown.request();
        let mut log = Log::default();
        let mut process = Fake::new(shutdown.clone());
        let script = Script(vec![Ok(b"x".to_vec())].into_iter());
        let lost = read_until_lost(
            script,
            &shutdown,
            &mut [0; 8],
            &mut presence(),
            &mut process,
            &mut log,
        );
        assert!(lost.unwrap().is_none());
        reconnect_loop("/nonexistent", &line(), &mut process, &mut [0; 8], &mut log).unwrap();
        assert_eq!((log.after_reads, process.beats), (0, 0));
    }

    #[test]
    fn a_missing_device_keeps_the_heartbeat_going() {
        let shutdown = Shutdown::manual();
        let mut process = Fake::new(shutdown.clone());
        let mut log = Log::default();
        // A stop arrives while the loop waits for a device that is not there.
        let stop = std::thread::spawn({
            let shutdown = shutdown.clone();
            move || {
                std::thread::sleep(Duration::from_millis(100));
                shutdown.request();
            }
        });
        reconnect_loop(
            "/nonexistent/tty",
            &line(),
            &mut process,
            &mut [0; 8],
            &mut log,
        )
        .unwrap();
        stop.join().unwrap();
        // The waits of 100 ms beat every 10 ms step; nothing was read, nothing reconnected.
        assert!(process.beats >= 5, "{} beats", process.beats);
        assert_eq!((log.after_reads, process.counters.reconnects), (0, 0));
    }
}
