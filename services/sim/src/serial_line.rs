//! The simulated device's serial line: a pseudo-terminal, optionally also reachable under a stable
//! link path, that can be unplugged and plugged back in. Unplugging closes the pseudo-terminal, so
//! a reader sees a hang-up and the device path disappears, as when a USB adapter drops off the bus;
//! plugging in creates a new one (a new `/dev/pts/N`) and re-points the link.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::{Context, Result};
use serialport::{SerialPort, TTYPort};

/// How long a write may wait for the reader before the tick's bytes are dropped. The pty holds
/// about 40 ms of frames; past that a real line would overrun the receiver. The simulator waits
/// longer than a real device would, because it shares the processor with the pipeline it feeds: a
/// stalled reader on a loaded machine delays frames (the sleeps catch up) instead of losing them.
const WRITE_TIMEOUT: Duration = Duration::from_millis(100);

/// One plugged-in pseudo-terminal.
struct Port {
    master: TTYPort,
    /// Held open so that the terminal outlives a reader that closes it (an acquisition restart):
    /// the bytes then wait in the terminal instead of failing the write.
    _slave: TTYPort,
    tty: String,
}

impl Port {
    fn create() -> Result<Self> {
        let (mut master, slave) = TTYPort::pair().context("cannot create a pseudo-terminal")?;
        let tty = slave
            .name()
            .context("the pseudo-terminal has no device name")?;
        master.set_timeout(WRITE_TIMEOUT)?;
        Ok(Self {
            master,
            _slave: slave,
            tty,
        })
    }
}

/// The simulated serial line: a pseudo-terminal the simulator writes frames into, optionally reached
/// through a fixed symlink, which can be unplugged and plugged in again as a new terminal.
pub struct SerialLine {
    link: Option<PathBuf>,
    /// `None` while unplugged.
    port: Option<Port>,
}

/// Points `link` at `target`, replacing whatever is there in one step (a symlink beside it, then a
/// rename), so that a reader never finds the path missing or half made while it is re-pointed.
fn point_link(link: &Path, target: &str) -> Result<()> {
    let mut tmp = link.as_os_str().to_owned();
    tmp.push(".new");
    let tmp = PathBuf::from(tmp);
    let _ = std::fs::remove_file(&tmp);
    std::os::unix::fs::symlink(target, &tmp)
        .and_then(|()| std::fs::rename(&tmp, link))
        .with_context(|| format!("cannot link {} to {target}", link.display()))
}

impl SerialLine {
    /// A plugged-in line; with `link`, the terminal is also reachable under that path.
    pub fn open(link: Option<PathBuf>) -> Result<Self> {
        let mut line = Self { link, port: None };
        line.plug()?;
        Ok(line)
    }

    /// The terminal's device path, `None` while unplugged.
    pub fn tty(&self) -> Option<&str> {
        self.port.as_ref().map(|p| p.tty.as_str())
    }

    /// Whether a terminal is in (the line is not unplugged).
    pub fn is_plugged(&self) -> bool {
        self.port.is_some()
    }

    /// Pulls the cable: the link goes first, so that nobody opens the old terminal again, then the
    /// terminal closes and its reader sees a hang-up.
    pub fn unplug(&mut self) {
        if let Some(link) = &self.link {
            let _ = std::fs::remove_file(link);
        }
        self.port = None;
    }

    /// Plugs a new terminal in (nothing happens when one is in) and points the link at it.
    pub fn plug(&mut self) -> Result<&str> {
        if self.port.is_none() {
            let port = Port::create()?;
            if let Some(link) = &self.link {
                point_link(link, &port.tty)?;
            }
            self.port = Some(port);
        }
        Ok(self.tty().unwrap_or_default())
    }

    /// Sends one tick's bytes; `false` when they were lost (unplugged, or nobody read them in
    /// time). Allocation-free.
    pub fn send(&mut self, bytes: &[u8]) -> bool {
        match &mut self.port {
            Some(port) => port.master.write_all(bytes).is_ok(),
            None => false,
        }
    }
}

impl Drop for SerialLine {
    fn drop(&mut self) {
        self.unplug();
    }
}

#[cfg(test)]
mod tests {
    use std::io::Read;

    use super::*;

    fn open_reader(path: &Path) -> TTYPort {
        serialport::new(path.to_string_lossy(), 921_600)
            .timeout(Duration::from_millis(200))
            .open_native()
            .expect("the link opens like a serial device")
    }

    #[test]
    fn unplugging_hangs_up_the_reader_and_removes_the_path_until_plugged_back() {
        let dir = std::env::temp_dir().join(format!("rins-line-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let link = dir.join("tty");
        let mut line = SerialLine::open(Some(link.clone())).unwrap();
        let first_tty = line.tty().unwrap().to_string();
        assert_eq!(
            std::fs::read_link(&link).unwrap(),
            PathBuf::from(&first_tty)
        );
        let mut reader = open_reader(&link);
        assert!(line.send(b"abc"));
        let mut buf = [0u8; 8];
        assert_eq!(reader.read(&mut buf).unwrap(), 3);

        line.unplug();
        assert!(!line.is_plugged() && line.tty().is_none());
        assert!(!line.send(b"lost"));
        assert!(
            std::fs::symlink_metadata(&link).is_err(),
            "the link must go"
        );
        // The reader sees the hang-up (an error or end of file), not a timeout.
        match reader.read(&mut buf) {
            Ok(n) => assert_eq!(n, 0),
            Err(e) => assert_ne!(e.kind(), std::io::ErrorKind::TimedOut, "{e}"),
        }

        line.plug().unwrap();
        assert!(line.is_plugged());
        let mut again = open_reader(&link);
        assert!(line.send(b"xyz"));
        assert_eq!(again.read(&mut buf).unwrap(), 3);
        assert_eq!(&buf[..3], b"xyz");
        drop(line);
        assert!(std::fs::symlink_metadata(&link).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
