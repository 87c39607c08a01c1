//! Opening the serial device, for acquisition and for `rins probe`: one place that knows the
//! driver's options and how its errors are worded.

use std::time::Duration;

use anyhow::{Result, anyhow};

/// Opens the serial device at `path` at `baud`, reads blocking at most `read_timeout`. The error
/// names the device and the operating system's reason (no such file, permission denied, not a
/// terminal).
pub fn open(path: &str, baud: u32, read_timeout: Duration) -> Result<serialport::TTYPort> {
    serialport::new(path, baud)
        .timeout(read_timeout)
        .open_native()
        .map_err(|e| anyhow!("cannot open serial device {path}: {e}"))
}
