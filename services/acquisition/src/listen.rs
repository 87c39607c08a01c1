//! Listens to a serial device for a while and returns what the decoder made of it, for
//! `rins probe`: the same driver and decoder acquisition uses, without publishing anything.

use std::io::Read;
use std::time::{Duration, Instant};

use anyhow::{Result, anyhow};
use rins_protocol::{Decoder, DeviceSpans, LineReport};
use rins_runtime::clock::monotonic_ns;
use rins_serial_reader::port;
use serialport::{ClearBuffer, SerialPort};

/// Read timeout while listening: short, so a listen ends on time on a silent line.
const READ_TIMEOUT: Duration = Duration::from_millis(50);

/// Opens `path` at `baud`, drops what the driver buffered before (bytes sent at another rate, or
/// long ago), reads for `seconds` and reports what arrived. A hang-up ends the listen early with
/// what was read until then; other read errors are returned, naming the device.
pub fn listen(path: &str, baud: u32, seconds: f64) -> Result<LineReport> {
    let mut port = port::open(path, baud, READ_TIMEOUT)?;
    port.clear(ClearBuffer::Input)
        .map_err(|e| anyhow!("cannot clear the input of {path}: {e}"))?;
    let mut decoder = Decoder::new();
    let mut spans = DeviceSpans::default();
    read_for(
        &mut port,
        path,
        Duration::from_secs_f64(seconds),
        &mut decoder,
        &mut spans,
    )?;
    Ok(LineReport::from_listen(&decoder.stats(), &spans, seconds))
}

/// Reads `port` for `length` into `decoder`, noting the device time of every frame in `spans`.
fn read_for(
    port: &mut serialport::TTYPort,
    path: &str,
    length: Duration,
    decoder: &mut Decoder,
    spans: &mut DeviceSpans,
) -> Result<()> {
    let mut buf = [0u8; 4096];
    let end = Instant::now() + length;
    while Instant::now() < end {
        match port.read(&mut buf) {
            // The other end hung up: nothing more will come.
            Ok(0) => break,
            Ok(n) => decoder.push(&buf[..n], monotonic_ns(), |f| spans.observe(&f)),
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::TimedOut | std::io::ErrorKind::Interrupted
                ) => {}
            Err(e) => return Err(anyhow!("cannot read serial device {path}: {e}")),
        }
    }
    Ok(())
}
