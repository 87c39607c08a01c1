//! When to restart a child that exited: exponential backoff, reset after a stable run, and a limit
//! on restarts within a sliding window after which the watchdog gives up on the child.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

/// What the watchdog does with a child that exceeded its restart limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GiveUp {
    /// Stop the whole pipeline; `rins up` exits with an error naming the child, and the service
    /// manager (`Restart=on-failure`) starts the deployment afresh.
    #[default]
    Shutdown,
    /// Leave the child down, keep the others running, and report it `given-up`.
    LeaveDown,
}

/// How a child is restarted, and when it is given up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestartPolicy {
    /// Delay before the first restart.
    pub initial_backoff: Duration,
    /// Upper bound of the doubling delay.
    pub max_backoff: Duration,
    /// A child that ran this long is considered healthy again: the next failure starts from
    /// `initial_backoff`.
    pub stable_after: Duration,
    /// At most this many restarts within `window`; one more and the watchdog gives up.
    pub max_restarts: u32,
    /// The window exits are counted in.
    pub window: Duration,
    /// What giving up the child does.
    pub give_up: GiveUp,
}

impl Default for RestartPolicy {
    fn default() -> Self {
        Self {
            initial_backoff: Duration::from_millis(10),
            max_backoff: Duration::from_secs(5),
            stable_after: Duration::from_secs(1),
            max_restarts: 20,
            window: Duration::from_secs(60),
            give_up: GiveUp::Shutdown,
        }
    }
}

impl RestartPolicy {
    /// Delay before restarting a child that has failed `consecutive_failures` times in a row
    /// (1 for the first failure).
    pub fn backoff(&self, consecutive_failures: u32) -> Duration {
        let doublings = consecutive_failures.saturating_sub(1).min(30);
        self.initial_backoff
            .saturating_mul(1u32 << doublings)
            .min(self.max_backoff)
    }

    /// Consecutive-failure count after a child that ran for `ran_for` exited.
    pub fn failures_after_exit(&self, previous_failures: u32, ran_for: Duration) -> u32 {
        if ran_for >= self.stable_after {
            1
        } else {
            previous_failures.saturating_add(1)
        }
    }
}

/// The largest `max_restarts` the configuration accepts. It bounds the ring of exit instants each
/// child keeps (16 bytes an entry), so that the ring is allocated once at start and never grows.
pub const MAX_RESTARTS_LIMIT: u32 = 10_000;

/// The exits of one child within the policy's window. Holds at most `max_restarts + 1` instants,
/// allocated once: recording an exit never allocates.
#[derive(Debug, Clone)]
pub struct RestartWindow {
    exits: VecDeque<Instant>,
    max_restarts: u32,
    window: Duration,
}

impl RestartWindow {
    /// A limit above [`MAX_RESTARTS_LIMIT`] (only possible for a policy not read from the
    /// configuration, which refuses it) is taken as that limit, keeping the ring bounded.
    pub fn new(policy: &RestartPolicy) -> Self {
        let max_restarts = policy.max_restarts.min(MAX_RESTARTS_LIMIT);
        Self {
            exits: VecDeque::with_capacity(max_restarts as usize + 1),
            max_restarts,
            window: policy.window,
        }
    }

    /// Records an exit at `now`; true when a restart is still within the limit.
    pub fn allow_restart(&mut self, now: Instant) -> bool {
        while self
            .exits
            .front()
            .is_some_and(|&t| now.saturating_duration_since(t) > self.window)
        {
            self.exits.pop_front();
        }
        if self.exits.len() > self.max_restarts as usize {
            self.exits.pop_front();
        }
        self.exits.push_back(now);
        self.exits.len() <= self.max_restarts as usize
    }

    /// Exits within the window, as of the last record.
    pub fn exits(&self) -> usize {
        self.exits.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backoff_doubles_up_to_the_cap() {
        let p = RestartPolicy {
            initial_backoff: Duration::from_millis(10),
            max_backoff: Duration::from_millis(100),
            stable_after: Duration::from_secs(1),
            ..RestartPolicy::default()
        };
        assert_eq!(p.backoff(1), Duration::from_millis(10));
        assert_eq!(p.backoff(2), Duration::from_millis(20));
        assert_eq!(p.backoff(4), Duration::from_millis(80));
        assert_eq!(p.backoff(5), Duration::from_millis(100));
        assert_eq!(p.backoff(u32::MAX), Duration::from_millis(100));
    }

    #[test]
    fn a_stable_run_resets_the_failure_count() {
        let p = RestartPolicy::default();
        assert_eq!(p.failures_after_exit(7, Duration::from_secs(60)), 1);
        assert_eq!(p.failures_after_exit(7, Duration::from_millis(5)), 8);
    }

    #[test]
    fn the_limit_counts_exits_within_the_sliding_window() {
        let p = RestartPolicy {
            max_restarts: 3,
            window: Duration::from_secs(10),
            ..RestartPolicy::default()
        };
        let t0 = Instant::now();
        let s = |secs: u64| t0 + Duration::from_secs(secs);
        let mut w = RestartWindow::new(&p);
        // Three exits in 10 s are restarted, the fourth within the window is one too many.
        assert!(w.allow_restart(s(0)));
        assert!(w.allow_restart(s(4)));
        assert!(w.allow_restart(s(8)));
        assert!(!w.allow_restart(s(9)));
        // Spread out, exits leave the window: 11 s after the first, three remain in it.
        let mut w = RestartWindow::new(&p);
        for t in [0, 4, 8] {
            assert!(w.allow_restart(s(t)));
        }
        assert!(w.allow_restart(s(11)));
        assert_eq!(w.exits(), 3);
        assert!(w.allow_restart(s(15)));
        assert!(!w.allow_restart(s(16)));
    }

    #[test]
    fn a_zero_limit_never_restarts() {
        let p = RestartPolicy {
            max_restarts: 0,
            ..RestartPolicy::default()
        };
        let mut w = RestartWindow::new(&p);
        assert!(!w.allow_restart(Instant::now()));
    }

    #[test]
    fn the_ring_never_grows_past_its_first_allocation() {
        let p = RestartPolicy {
            max_restarts: 5,
            window: Duration::from_secs(3600),
            ..RestartPolicy::default()
        };
        let mut w = RestartWindow::new(&p);
        let capacity = w.exits.capacity();
        let t0 = Instant::now();
        for i in 0..1_000 {
            w.allow_restart(t0 + Duration::from_millis(i));
        }
        assert_eq!(w.exits(), 6);
        assert_eq!(w.exits.capacity(), capacity);
        // A limit beyond what the configuration accepts is clamped, not allocated.
        let huge = RestartWindow::new(&RestartPolicy {
            max_restarts: u32::MAX,
            ..RestartPolicy::default()
        });
        assert!(huge.exits.capacity() <= MAX_RESTARTS_LIMIT as usize + 1 + 64);
    }

    #[test]
    fn exits_exactly_one_window_apart_still_count() {
        let p = RestartPolicy {
            max_restarts: 1,
            window: Duration::from_secs(10),
            ..RestartPolicy::default()
        };
        let t0 = Instant::now();
        let mut w = RestartWindow::new(&p);
        assert!(w.allow_restart(t0));
        assert!(!w.allow_restart(t0 + Duration::from_secs(10)));
        let mut w = RestartWindow::new(&p);
        assert!(w.allow_restart(t0));
        assert!(w.allow_restart(t0 + Duration::from_millis(10_001)));
    }
}
