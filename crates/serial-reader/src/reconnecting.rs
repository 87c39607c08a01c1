//! The one loop every serial reader runs: open the device, read it until it is lost, wait with
//! backoff, open it again, until a stop is requested. The loop owns the decisions (when to retry,
//! how long to wait, what counts as lost); the reader's [`LineEvents`] say what each event means
//! to it (logging, decoding, counters, heartbeats).

use std::io::Read;
use std::time::Duration;

use anyhow::Result;
use rins_runtime::clock::monotonic_ns;
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
    /// The device opened: the first time, or back after an absence.
    fn opened(&mut self, opened: Opened, presence: &Presence);
    /// A read returned `bytes` (never empty).
    fn bytes(&mut self, bytes: &[u8]);
    /// After every read that did not lose the device, bytes or timeout: the place for statistics
    /// and the heartbeat. An error ends the loop.
    fn after_read(&mut self) -> Result<()>;
    /// The open device was lost with `error`; the loop waits `delay` before reopening it.
    fn lost(&mut self, error: &std::io::Error, delay: Duration, presence: &Presence);
    /// Every step of a wait between attempts (the heartbeat). An error ends the loop.
    fn waiting(&mut self) -> Result<()>;
}

/// Reads the device at `path` with the settings of `line` into `events` until `shutdown` is
/// requested, reading at most `buf.len()` bytes at a time. A missing or lost device is retried
/// with the line's backoff, never given up on. Returns the first error of `events`.
pub fn read_reconnecting(
    path: &str,
    line: &SerialLineConfig,
    shutdown: &Shutdown,
    buf: &mut [u8],
    events: &mut impl LineEvents,
) -> Result<()> {
    let mut presence = Presence::new(line.backoff());
    while !shutdown.requested() {
        let port = match port::open(path, line.baud, line.read_timeout()) {
            Ok(port) => port,
            Err(e) => {
                let retry = presence.open_failed(monotonic_ns());
                events.open_failed(&e, &retry, &presence);
                wait_for_retry(retry.delay, shutdown, || events.waiting())?;
                continue;
            }
        };
        let opened = presence.opened(monotonic_ns());
        events.opened(opened, &presence);
        let lost = read_until_lost(port, shutdown, buf, &mut presence, events)?;
        if let Some(e) = lost
            && !shutdown.requested()
        {
            let delay = presence.lost(monotonic_ns());
            events.lost(&e, delay, &presence);
            wait_for_retry(delay, shutdown, || events.waiting())?;
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
    events: &mut impl LineEvents,
) -> Result<Option<std::io::Error>> {
    while !shutdown.requested() {
        match port.read(buf) {
            // End of file: the other end hung up.
            Ok(0) => return Ok(Some(std::io::ErrorKind::UnexpectedEof.into())),
            Ok(n) => {
                presence.data_arrived();
                events.bytes(&buf[..n]);
            }
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                ) => {}
            Err(e) => return Ok(Some(e)),
        }
        events.after_read()?;
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

    #[derive(Default)]
    struct Log {
        bytes: Vec<u8>,
        after_reads: usize,
    }

    impl LineEvents for Log {
        fn open_failed(&mut self, _: &anyhow::Error, _: &Retry, _: &Presence) {}
        fn opened(&mut self, _: Opened, _: &Presence) {}
        fn bytes(&mut self, bytes: &[u8]) {
            self.bytes.extend_from_slice(bytes);
        }
        fn after_read(&mut self) -> Result<()> {
            self.after_reads += 1;
            Ok(())
        }
        fn lost(&mut self, _: &std::io::Error, _: Duration, _: &Presence) {}
        fn waiting(&mut self) -> Result<()> {
            Ok(())
        }
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
        let lost = read_until_lost(script, &Shutdown::manual(), &mut [0; 8], &mut p, &mut log)
            .unwrap()
            .expect("the end of the script is a hang-up");
        assert_eq!(lost.kind(), ErrorKind::UnexpectedEof);
        // Four reads before the hang-up, each followed by `after_read`; the hang-up is not.
        assert_eq!((log.bytes.as_slice(), log.after_reads), (&b"abc"[..], 4));
        // The device delivered data: its loss starts the shortest backoff.
        assert_eq!(p.lost(1), Duration::from_millis(10));

        let script = Script(vec![Err(ErrorKind::BrokenPipe.into())].into_iter());
        let lost = read_until_lost(script, &Shutdown::manual(), &mut [0; 8], &mut p, &mut log)
            .unwrap()
            .expect("an I/O error is a loss");
        assert_eq!(lost.kind(), ErrorKind::BrokenPipe);
    }

    #[test]
    fn a_stop_ends_the_loops_without_a_loss() {
        let shutdown = Shutdown::manual();
        shutdown.request();
        let mut log = Log::default();
        let script = Script(vec![Ok(b"x".to_vec())].into_iter());
        let lost = read_until_lost(script, &shutdown, &mut [0; 8], &mut presence(), &mut log);
        assert!(lost.unwrap().is_none());
        let line = SerialLineConfig {
            port: None,
            baud: 9600,
            read_timeout_ms: 50,
            reconnect_initial_ms: 10,
            reconnect_max_ms: 1000,
        };
        read_reconnecting("/nonexistent", &line, &shutdown, &mut [0; 8], &mut log).unwrap();
        assert_eq!(log.after_reads, 0);
    }
}
