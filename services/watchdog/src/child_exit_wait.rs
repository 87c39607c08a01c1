//! The watchdog's sleep between turns, cut short when a child exits. SIGCHLD is blocked in the
//! watchdog's thread and taken with `sigtimedwait`, so a killed service is reaped and restarted at
//! once instead of at the next turn: the loop can then turn slowly (fewer wake-ups) without
//! lengthening the output gap a restart leaves.
//!
//! The mask is the calling thread's, inherited by the threads it starts later; each child starts
//! with an empty mask (the standard library clears it in the child before `exec`). Where the
//! signal cannot be waited for, the sleep is a plain sleep of the whole period.

use std::time::Duration;

/// See the module documentation.
pub struct ChildExitWait {
    set: Option<libc::sigset_t>,
}

impl ChildExitWait {
    /// Blocks SIGCHLD in the calling thread (the one that then calls [`Self::sleep`]).
    pub fn new() -> Self {
        // SAFETY: sigemptyset/sigaddset fill a local set; pthread_sigmask reads it and changes
        // only this thread's mask.
        let set = unsafe {
            let mut set: libc::sigset_t = std::mem::zeroed();
            let blocked = libc::sigemptyset(&mut set) == 0
                && libc::sigaddset(&mut set, libc::SIGCHLD) == 0
                && libc::pthread_sigmask(libc::SIG_BLOCK, &set, std::ptr::null_mut()) == 0;
            blocked.then_some(set)
        };
        if set.is_none() {
            tracing::warn!("cannot block SIGCHLD: children's exits are seen at the loop's turns");
        }
        Self { set }
    }

    /// Sleeps `timeout`, or less when a child exits (or a signal arrives) meanwhile.
    pub fn sleep(&self, timeout: Duration) {
        let Some(set) = &self.set else {
            std::thread::sleep(timeout);
            return;
        };
        let ts = libc::timespec {
            tv_sec: libc::time_t::try_from(timeout.as_secs()).unwrap_or(libc::time_t::MAX),
            tv_nsec: libc::c_long::from(timeout.subsec_nanos() as i32),
        };
        // SAFETY: the set and the timespec live across the call; no siginfo is asked for.
        let r = unsafe { libc::sigtimedwait(set, std::ptr::null_mut(), &ts) };
        if r < 0 {
            let errno = std::io::Error::last_os_error().raw_os_error();
            // EAGAIN: the time passed; EINTR: another signal (a stop) came. Anything else means
            // the wait did not happen: sleep instead, never spin.
            if !matches!(errno, Some(libc::EAGAIN) | Some(libc::EINTR)) {
                std::thread::sleep(timeout);
            }
        }
    }
}

impl Default for ChildExitWait {
    fn default() -> Self {
        Self::new()
    }
}

impl Drop for ChildExitWait {
    /// Unblocks SIGCHLD again (a pending one is discarded: its default action is to ignore it).
    fn drop(&mut self) {
        if let Some(set) = &self.set {
            // SAFETY: as in `new`.
            unsafe { libc::pthread_sigmask(libc::SIG_UNBLOCK, set, std::ptr::null_mut()) };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sleep_without_any_child_lasts_its_period() {
        let wait = ChildExitWait::new();
        let start = std::time::Instant::now();
        wait.sleep(Duration::from_millis(30));
        assert!(start.elapsed() >= Duration::from_millis(25));
    }
}
