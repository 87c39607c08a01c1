//! Signals to processes a test started: its own children, or the children of a pipeline it runs
//! (by the pid the watchdog reports).

use std::io;

/// A signal a test sends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Signal {
    /// SIGTERM: stop as an operator asks.
    Terminate,
    /// SIGKILL: die at once, nothing cleaned up.
    Kill,
    /// SIGSTOP: hang (stopped, not dead).
    Stop,
    /// SIGCONT: resume after [`Signal::Stop`].
    Continue,
    /// SIGHUP: the controlling terminal went away.
    Hangup,
    /// SIGUSR1: a user-defined signal nobody asked for.
    User1,
}

impl Signal {
    /// The signal number.
    fn number(self) -> libc::c_int {
        match self {
            Signal::Terminate => libc::SIGTERM,
            Signal::Kill => libc::SIGKILL,
            Signal::Stop => libc::SIGSTOP,
            Signal::Continue => libc::SIGCONT,
            Signal::Hangup => libc::SIGHUP,
            Signal::User1 => libc::SIGUSR1,
        }
    }
}

/// The pid as the kernel's type, or an error for a number no process can have.
fn pid_t(pid: u64) -> io::Result<libc::pid_t> {
    libc::pid_t::try_from(pid)
        .ok()
        .filter(|&p| p > 0)
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, format!("pid {pid}")))
}

/// Sends `signal` to process `pid` (e.g. `u64::from(child.id())`, or a pid from a status
/// report). The error is the operating system's (no such process, not permitted).
pub fn send_signal(pid: u64, signal: Signal) -> io::Result<()> {
    let pid = pid_t(pid)?;
    // SAFETY: kill(2) takes plain integers and touches no memory of ours; pid > 0 addresses one
    // process, never a group.
    if unsafe { libc::kill(pid, signal.number()) } == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Whether a process `pid` exists (a zombie, not yet reaped, still does).
pub fn process_exists(pid: u64) -> bool {
    let Ok(pid) = pid_t(pid) else {
        return false;
    };
    // SAFETY: signal 0 only checks that the pid exists and may be signalled.
    unsafe { libc::kill(pid, 0) == 0 }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Command;

    #[test]
    fn a_killed_child_exits_by_the_signal_and_then_is_gone() {
        use std::os::unix::process::ExitStatusExt;
        let mut child = Command::new("sleep").arg("30").spawn().unwrap();
        let pid = u64::from(child.id());
        assert!(process_exists(pid));
        send_signal(pid, Signal::Kill).unwrap();
        let status = child.wait().unwrap();
        assert_eq!(status.signal(), Some(libc::SIGKILL));
        assert!(!process_exists(pid));
    }

    #[test]
    fn impossible_pids_are_refused_without_a_signal() {
        assert_eq!(
            send_signal(0, Signal::Terminate).unwrap_err().kind(),
            io::ErrorKind::InvalidInput
        );
        assert!(send_signal(u64::MAX, Signal::Kill).is_err());
        assert!(!process_exists(0));
    }
}
