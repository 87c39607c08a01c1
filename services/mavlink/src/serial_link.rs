//! The MAVLink stream over a serial port, as to an autopilot's telemetry port. Two threads per
//! port: the writer writes the frames the link's sender hands it; the reader owns the port, reads
//! the byte stream back into frames (TIMESYNC and commands are acted on as from a UDP peer) and
//! opens the port again, with a growing back-off, when it disappears (a USB adapter unplugged) or
//! is not there yet. Neither ever holds up the navigation loop: the frames reach the writer
//! through a bounded queue, and what cannot be written is counted.

use std::io::{self, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;
use std::time::Duration;

use crossbeam_channel::Receiver;
use mavlink::error::MessageReadError;
use mavlink::{MAVLinkMessageRaw, MavlinkReader, MavlinkVersion, Message};
use serialport::{SerialPort, TTYPort};

use crate::dialect::MavMessage;
use crate::inbound::{Inbound, Origin, READ_POLL};
use crate::speaker::MAX_FRAME;

/// The first wait before opening a lost port again; it doubles after each failure.
const REOPEN_FIRST: Duration = Duration::from_millis(100);
/// The longest wait between attempts: an adapter plugged back in is found within this.
const REOPEN_MAX: Duration = Duration::from_secs(2);
/// How long the writer waits for room in the port's output buffer before it gives a frame up: a
/// line that does not drain in this time is behind by far more than the stream's pace.
const WRITE_TIMEOUT: Duration = Duration::from_millis(50);

/// One framed message on its way to a serial port, held by value so that queueing it does not
/// allocate.
pub(crate) struct Frame {
    bytes: [u8; MAX_FRAME],
    len: usize,
}

impl Frame {
    /// The frame `bytes` (at most [`MAX_FRAME`]; the excess, which a MAVLink frame never has, is
    /// cut).
    pub(crate) fn new(bytes: &[u8]) -> Self {
        let len = bytes.len().min(MAX_FRAME);
        let mut frame = Self {
            bytes: [0; MAX_FRAME],
            len,
        };
        frame.bytes[..len].copy_from_slice(&bytes[..len]);
        frame
    }

    fn as_bytes(&self) -> &[u8] {
        &self.bytes[..self.len]
    }
}

/// The wait before the opening attempt after `failures` failed ones: [`REOPEN_FIRST`] doubled
/// each time, at most [`REOPEN_MAX`].
pub fn reopen_delay(failures: u32) -> Duration {
    REOPEN_FIRST
        .checked_mul(1u32.checked_shl(failures).unwrap_or(u32::MAX))
        .map_or(REOPEN_MAX, |d| d.min(REOPEN_MAX))
}

/// The write side of the open port, `None` while it is away; the reader puts it in and takes it
/// out.
type WriteSide = Arc<Mutex<Option<TTYPort>>>;

/// Writes `bytes` to the port in `side`; `false` when there is none or the write failed (then a
/// failure other than a full buffer takes the port out: it is gone, and the reader reopens it).
fn write_to(side: &Mutex<Option<TTYPort>>, bytes: &[u8]) -> bool {
    let mut side = side.lock().unwrap_or_else(PoisonError::into_inner);
    let Some(port) = side.as_mut() else {
        return false;
    };
    match port.write_all(bytes) {
        Ok(()) => true,
        Err(e) if e.kind() == io::ErrorKind::TimedOut => false,
        Err(_) => {
            *side = None;
            false
        }
    }
}

/// Starts the reader and the writer of the serial port at `path`, `baud`; the writer ends when
/// `frames` closes, the reader when `stop` is set.
pub(crate) fn start(
    path: String,
    baud: u32,
    frames: Receiver<Frame>,
    inbound: Inbound,
    stop: Arc<AtomicBool>,
) -> io::Result<[JoinHandle<()>; 2]> {
    let side: WriteSide = Arc::new(Mutex::new(None));
    let writer_side = Arc::clone(&side);
    let counters = Arc::clone(&inbound.counters);
    let writer = std::thread::Builder::new()
        .name("mavlink-serial-tx".into())
        .spawn(move || {
            for frame in frames {
                let counter = if write_to(&writer_side, frame.as_bytes()) {
                    &counters.sent
                } else {
                    &counters.serial_dropped
                };
                counter.fetch_add(1, Ordering::Relaxed);
            }
        })?;
    let reader = PortReader {
        path,
        baud,
        side,
        inbound,
        stop,
    };
    let reader = std::thread::Builder::new()
        .name("mavlink-serial-rx".into())
        .spawn(move || reader.run())?;
    Ok([writer, reader])
}

/// Opens, reads and reopens one serial port.
struct PortReader {
    path: String,
    baud: u32,
    side: WriteSide,
    inbound: Inbound,
    stop: Arc<AtomicBool>,
}

impl PortReader {
    fn stopped(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// Sleeps `delay`, waking early when the link stops.
    fn pause(&self, delay: Duration) {
        let mut left = delay;
        while !left.is_zero() && !self.stopped() {
            let step = left.min(READ_POLL);
            std::thread::sleep(step);
            left -= step;
        }
    }

    /// The port, reading with [`READ_POLL`] as timeout, and its write side in [`Self::side`].
    fn open(&self) -> Result<TTYPort, serialport::Error> {
        let port = serialport::new(&self.path, self.baud)
            .timeout(READ_POLL)
            .open_native()?;
        let mut write_side = port.try_clone_native()?;
        write_side.set_timeout(WRITE_TIMEOUT)?;
        *self.side.lock().unwrap_or_else(PoisonError::into_inner) = Some(write_side);
        Ok(port)
    }

    fn run(self) {
        let counters = Arc::clone(&self.inbound.counters);
        // Failed attempts since the port was last open: the back-off, and whether to log.
        let mut failures = 0u32;
        let mut ever_open = false;
        while !self.stopped() {
            let port = match self.open() {
                Ok(port) => port,
                Err(e) => {
                    if failures == 0 {
                        tracing::warn!(
                            port = %self.path,
                            baud = self.baud,
                            "cannot open the MAVLink serial port: {e}; trying again with back-off \
                             (further attempts are not logged)"
                        );
                    }
                    self.pause(reopen_delay(failures));
                    failures = failures.saturating_add(1);
                    continue;
                }
            };
            if ever_open || failures > 0 {
                counters.serial_reopened.fetch_add(1, Ordering::Relaxed);
                tracing::info!(port = %self.path, attempts = failures + 1, "MAVLink serial port open again");
            }
            failures = 0;
            ever_open = true;
            let why = self.read_until_lost(MavlinkReader::new(port));
            *self.side.lock().unwrap_or_else(PoisonError::into_inner) = None;
            if let Some(why) = why {
                counters.serial_lost.fetch_add(1, Ordering::Relaxed);
                tracing::warn!(port = %self.path, "MAVLink serial port lost: {why}; reopening");
                self.pause(REOPEN_FIRST);
            }
        }
    }

    /// Reads frames and acts on them until the link stops (`None`) or the port fails (why).
    fn read_until_lost(&self, mut reader: MavlinkReader<TTYPort>) -> Option<io::Error> {
        let mut frame = [0u8; MAX_FRAME];
        let origin = Origin::Port(&self.path);
        while !self.stopped() {
            // The writer took the port out: its write failed for good.
            if self
                .side
                .lock()
                .unwrap_or_else(PoisonError::into_inner)
                .is_none()
            {
                return Some(io::Error::other("a write failed"));
            }
            let raw = match reader.read_raw_message::<MavMessage>(MavlinkVersion::V2) {
                Ok(MAVLinkMessageRaw::V2(raw)) => raw,
                Ok(MAVLinkMessageRaw::V1(_)) | Err(MessageReadError::Parse(_)) => {
                    self.undecodable();
                    continue;
                }
                Err(MessageReadError::Io(e))
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut
                            | io::ErrorKind::WouldBlock
                            | io::ErrorKind::Interrupted
                    ) =>
                {
                    continue;
                }
                // End of file or an error: the device hung up or went away.
                Err(MessageReadError::Io(e)) => return Some(e),
            };
            match MavMessage::parse(MavlinkVersion::V2, raw.message_id(), raw.payload()) {
                Ok(msg) => {
                    let reply = |bytes: &[u8]| write_to(&self.side, bytes);
                    self.inbound
                        .on_message(&raw, msg, origin, &mut frame, reply);
                }
                Err(_) => self.undecodable(),
            }
        }
        None
    }

    fn undecodable(&self) {
        self.inbound
            .counters
            .undecodable
            .fetch_add(1, Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reopening_backs_off_doubling_up_to_the_longest_wait() {
        let waits: Vec<u64> = (0..7).map(|k| reopen_delay(k).as_millis() as u64).collect();
        assert_eq!(waits, [100, 200, 400, 800, 1600, 2000, 2000]);
        assert_eq!(reopen_delay(40), REOPEN_MAX);
        assert_eq!(reopen_delay(u32::MAX), REOPEN_MAX);
    }

    #[test]
    fn a_frame_keeps_its_bytes_and_never_more_than_the_largest_frame() {
        let bytes: Vec<u8> = (0..=255).collect();
        assert_eq!(Frame::new(&bytes[..12]).as_bytes(), &bytes[..12]);
        let long = vec![7u8; MAX_FRAME + 5];
        assert_eq!(Frame::new(&long).as_bytes().len(), MAX_FRAME);
    }

    #[test]
    fn nothing_is_written_while_the_port_is_away() {
        assert!(!write_to(&Mutex::new(None), b"\xfd"));
    }
}
