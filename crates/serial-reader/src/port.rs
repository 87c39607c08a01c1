//! Opening the serial device, for every reader of a serial line and for `rins probe`: one place
//! that knows the driver's options and how its errors are worded.

use std::os::fd::AsRawFd;
use std::time::Duration;

use anyhow::{Result, anyhow};

/// Opens the serial device at `path` at `baud`, reads blocking at most `read_timeout`. The error
/// names the device and the operating system's reason (no such file, permission denied, not a
/// terminal).
pub fn open(path: &str, baud: u32, read_timeout: Duration) -> Result<serialport::TTYPort> {
    serialport::new(path, baud)
        .timeout(read_timeout)
        .open_native()
        .map_err(|e| {
            // The driver words ENOTTY as the historical "Not a typewriter", and a port held by
            // another reader as a lock failure: say what each means.
            let hint = if e.kind() == serialport::ErrorKind::NoDevice {
                " (another program has it open: a running `rins up`?)"
            } else if openable_but_not_a_terminal(path) {
                " (not a terminal device, so not a serial port)"
            } else {
                ""
            };
            anyhow!("cannot open serial device {path}: {e}{hint}")
        })
}

/// Whether `path` opens as a file that is no terminal (a regular file, /dev/null).
fn openable_but_not_a_terminal(path: &str) -> bool {
    std::fs::File::open(path).is_ok_and(|f| {
        // SAFETY: isatty only inspects the descriptor, which `f` keeps open for the call.
        unsafe { libc::isatty(f.as_raw_fd()) == 0 }
    })
}
