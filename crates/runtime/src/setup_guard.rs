//! A bound on a tool's set-up. Joining a deployment and opening ports are calls into iceoryx2 that
//! do not look at the stop flag, and some damaged files make them wait without a limit (a segment
//! truncated to nothing is waited on for ever). While a guard is armed, a thread of its own ends
//! the process, with a message, when the set-up outlasts its limit or a stop signal arrives: a
//! tool given a timeout keeps it, and a tool told to stop stops.

use std::io::Write;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use crate::shutdown::Shutdown;

/// Exit status of a process the guard ends.
pub const GUARD_EXIT: i32 = 1;
/// How often the guard looks at the clock and the stop flag.
const POLL: Duration = Duration::from_millis(10);

/// Ends the process if the set-up it guards is still going on at its limit, or when a stop is
/// requested meanwhile. Disarmed by [`SetupGuard::disarm`] or when dropped.
pub struct SetupGuard {
    done: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl SetupGuard {
    /// Guards `what` (e.g. `echo: joining the deployment on prefix "rins_0_"`) for at most `limit`
    /// (none: until a stop only) and stops on `shutdown`'s flag (none: the process's own handler,
    /// [`Shutdown::installed`], when one is installed; otherwise a stop signal ends the process
    /// anyway).
    pub fn arm(what: String, limit: Option<Duration>, shutdown: Option<Shutdown>) -> Self {
        let done = Arc::new(AtomicBool::new(false));
        let shutdown = shutdown.or_else(Shutdown::installed);
        let deadline = limit.map(|l| Instant::now() + l);
        let flag = Arc::clone(&done);
        let thread = std::thread::Builder::new()
            .name("setup-guard".into())
            .spawn(move || {
                while !flag.load(Ordering::Acquire) {
                    if shutdown.as_ref().is_some_and(Shutdown::requested) {
                        end(&format!(
                            "rins: {what}: stopped by a signal before it was set up"
                        ));
                    }
                    if let (Some(at), Some(limit)) = (deadline, limit)
                        && Instant::now() >= at
                    {
                        end(&format!(
                            "rins: error: {what}: not done within {:.1} s; iceoryx2 did not \
                             answer (a damaged file of the deployment?)",
                            limit.as_secs_f64()
                        ));
                    }
                    std::thread::sleep(POLL);
                }
            })
            .ok();
        Self { done, thread }
    }

    /// The set-up is done: the guard stops watching.
    pub fn disarm(self) {}
}

impl Drop for SetupGuard {
    fn drop(&mut self) {
        self.done.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Writes `message` and ends the process at once: the thread it interrupts may hold iceoryx2's
/// state in any condition, so nothing of it is run down.
fn end(message: &str) -> ! {
    let mut err = std::io::stderr().lock();
    let _ = writeln!(err, "{message}");
    let _ = err.flush();
    // SAFETY: _exit ends the process without running destructors or atexit handlers, which is
    // what is wanted while another thread is inside iceoryx2.
    unsafe { libc::_exit(GUARD_EXIT) }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CHILD_ENV: &str = "RINS_SETUP_GUARD_CHILD";
    const THIS_TEST: &str =
        "setup_guard::tests::a_set_up_past_its_limit_or_told_to_stop_ends_the_process_saying_so";

    /// Run again as a child process of itself (the guard ends the process it is in): a set-up that
    /// never ends is ended at its limit, or at once when a stop is requested, with status
    /// [`GUARD_EXIT`] and a message saying which.
    #[test]
    fn a_set_up_past_its_limit_or_told_to_stop_ends_the_process_saying_so() {
        if let Ok(mode) = std::env::var(CHILD_ENV) {
            let stop = Shutdown::manual();
            let _guard = if mode == "limit" {
                SetupGuard::arm("test set-up".into(), Some(Duration::from_millis(200)), None)
            } else {
                let guard = SetupGuard::arm("test set-up".into(), None, Some(stop.clone()));
                stop.request();
                guard
            };
            // A set-up that never ends.
            std::thread::sleep(Duration::from_secs(20));
            return;
        }
        for (mode, expected) in [
            ("limit", "rins: error: test set-up: not done within 0.2 s"),
            ("stop", "rins: test set-up: stopped by a signal"),
        ] {
            let started = Instant::now();
            let out = std::process::Command::new(std::env::current_exe().unwrap())
                .args(["--exact", THIS_TEST, "--nocapture", "--test-threads", "1"])
                .env(CHILD_ENV, mode)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(GUARD_EXIT), "{mode}: {err}");
            assert!(err.contains(expected), "{mode}: {err}");
            assert!(started.elapsed() < Duration::from_secs(10), "{mode}");
        }
    }

    /// A disarmed guard, or one dropped, ends nothing: the test process goes on.
    #[test]
    fn a_guard_disarmed_in_time_does_nothing() {
        let guard = SetupGuard::arm("test".into(), Some(Duration::from_millis(200)), None);
        guard.disarm();
        let stop = Shutdown::manual();
        let guard = SetupGuard::arm("test".into(), None, Some(stop.clone()));
        drop(guard);
        stop.request();
        std::thread::sleep(Duration::from_millis(300));
    }
}
