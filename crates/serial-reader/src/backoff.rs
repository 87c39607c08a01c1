//! Exponential backoff between attempts to open a serial device that is not there (not plugged in
//! yet, or gone after a disconnect). Short first delays find a device that comes straight back
//! (a USB adapter re-enumerating takes tens of milliseconds); doubling keeps a device that stays
//! away from costing more than one attempt per `max`; the cap bounds how late a returning device
//! is noticed: at most `max` after it is back, since no two attempts are further apart.

use std::time::Duration;

/// Delay before retry number `attempt` (0 for the first retry): `initial`·2^attempt, at most
/// `max`. Saturates instead of overflowing, however many attempts.
pub fn backoff_delay(attempt: u32, initial: Duration, max: Duration) -> Duration {
    let factor = 1u32.checked_shl(attempt).unwrap_or(u32::MAX);
    initial.saturating_mul(factor).min(max)
}

/// Time from the first failure to retry number `attempt` (the sum of the delays before it): when
/// each attempt happens, for bounds on how late a returning device is found.
pub fn retry_time(attempt: u32, initial: Duration, max: Duration) -> Duration {
    (0..attempt)
        .map(|k| backoff_delay(k, initial, max))
        .fold(Duration::ZERO, Duration::saturating_add)
}

/// The retries of one episode of absence: hands out the delays in order and starts again after
/// the device has worked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Backoff {
    initial: Duration,
    max: Duration,
    attempt: u32,
}

impl Backoff {
    /// A backoff starting at `initial`, doubling up to `max`.
    pub fn new(initial: Duration, max: Duration) -> Self {
        Self {
            initial,
            max,
            attempt: 0,
        }
    }

    /// The delay before the next attempt; the one after is twice as long, up to the cap.
    pub fn next_delay(&mut self) -> Duration {
        let delay = backoff_delay(self.attempt, self.initial, self.max);
        self.attempt = self.attempt.saturating_add(1);
        delay
    }

    /// Retries handed out since the last reset.
    pub fn attempts(&self) -> u32 {
        self.attempt
    }

    /// The device works again: the next episode starts with the shortest delay.
    pub fn reset(&mut self) {
        self.attempt = 0;
    }

    /// The first delay, and the delay after a reset.
    pub fn initial(&self) -> Duration {
        self.initial
    }

    /// The longest delay.
    pub fn max(&self) -> Duration {
        self.max
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: fn(u64) -> Duration = Duration::from_millis;

    #[test]
    fn delays_double_from_the_first_up_to_the_cap() {
        let delays: Vec<u64> = (0..10)
            .map(|k| backoff_delay(k, MS(10), MS(1000)).as_millis() as u64)
            .collect();
        assert_eq!(delays, [10, 20, 40, 80, 160, 320, 640, 1000, 1000, 1000]);
        // No overflow, however long the device stays away.
        assert_eq!(backoff_delay(31, MS(10), MS(1000)), MS(1000));
        assert_eq!(backoff_delay(32, MS(10), MS(1000)), MS(1000));
        assert_eq!(backoff_delay(u32::MAX, MS(10), MS(1000)), MS(1000));
        assert_eq!(
            backoff_delay(u32::MAX, Duration::MAX, Duration::MAX),
            Duration::MAX
        );
        // A cap below the first delay wins.
        assert_eq!(backoff_delay(0, MS(50), MS(20)), MS(20));
    }

    #[test]
    fn retries_happen_at_the_running_sum_and_never_further_apart_than_the_cap() {
        let at = |k| retry_time(k, MS(10), MS(1000)).as_millis() as u64;
        assert_eq!(
            (0..10).map(at).collect::<Vec<_>>(),
            [0, 10, 30, 70, 150, 310, 630, 1270, 2270, 3270]
        );
        // A device back after an outage of T is found by the first retry at or after T, which
        // is less than the cap later.
        for outage_ms in [0, 5, 100, 999, 1000, 1001, 1271, 5000] {
            let found = (0..).map(at).find(|&t| t >= outage_ms).unwrap();
            assert!(found - outage_ms <= 1000, "{outage_ms}: {found}");
        }
    }

    #[test]
    fn backoff_hands_out_delays_in_order_and_restarts_after_a_reset() {
        let mut b = Backoff::new(MS(10), MS(40));
        let first: Vec<Duration> = (0..4).map(|_| b.next_delay()).collect();
        assert_eq!(first, [MS(10), MS(20), MS(40), MS(40)]);
        assert_eq!(b.attempts(), 4);
        b.reset();
        assert_eq!((b.attempts(), b.next_delay()), (0, MS(10)));
        assert_eq!((b.initial(), b.max()), (MS(10), MS(40)));
    }
}
