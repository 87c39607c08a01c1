//! When to restart a child that exited: exponential backoff, reset after a stable run.

use std::time::Duration;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestartPolicy {
    /// Delay before the first restart.
    pub initial_backoff: Duration,
    /// Upper bound of the doubling delay.
    pub max_backoff: Duration,
    /// A child that ran this long is considered healthy again: the next failure starts from
    /// `initial_backoff`.
    pub stable_after: Duration,
}

impl Default for RestartPolicy {
    fn default() -> Self {
        Self {
            initial_backoff: Duration::from_millis(10),
            max_backoff: Duration::from_secs(5),
            stable_after: Duration::from_secs(1),
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn backoff_doubles_up_to_the_cap() {
        let p = RestartPolicy {
            initial_backoff: Duration::from_millis(10),
            max_backoff: Duration::from_millis(100),
            stable_after: Duration::from_secs(1),
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
}
