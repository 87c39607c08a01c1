//! CLOCK_MONOTONIC in nanoseconds: the one time base for latency stamps (never wall clock).

/// Nanoseconds since an arbitrary fixed point (boot), shared by every process on the machine.
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the timespec we own; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// Nanoseconds of the system's real time (CLOCK_REALTIME, since 1970), the clock ROS nodes stamp
/// with; 0 for a clock set before 1970.
pub fn realtime_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the timespec we own; CLOCK_REALTIME always exists.
    unsafe { libc::clock_gettime(libc::CLOCK_REALTIME, &mut ts) };
    u64::try_from(ts.tv_sec).map_or(0, |s| s * 1_000_000_000 + ts.tv_nsec as u64)
}

/// `monotonic` (a CLOCK_MONOTONIC stamp) on the real-time clock, as of now: the two clocks'
/// current difference added (a real-time clock stepped since moves the result with it).
pub fn monotonic_to_realtime_ns(monotonic: u64) -> u64 {
    let (real, mono) = (realtime_ns(), monotonic_ns());
    real.saturating_sub(mono.saturating_sub(monotonic))
}

/// Sleeps until CLOCK_MONOTONIC reaches `deadline_ns` (at once when it has); a signal may end the
/// sleep early, so a caller that must not act before the deadline reads the clock again.
pub fn sleep_until(deadline_ns: u64) {
    let ts = libc::timespec {
        tv_sec: (deadline_ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (deadline_ns % 1_000_000_000) as libc::c_long,
    };
    // SAFETY: an absolute sleep on the monotonic clock with a timespec we own; no remainder is
    // written for an absolute sleep.
    unsafe {
        libc::clock_nanosleep(
            libc::CLOCK_MONOTONIC,
            libc::TIMER_ABSTIME,
            &ts,
            std::ptr::null_mut(),
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monotonic_never_goes_back() {
        let mut last = monotonic_ns();
        for _ in 0..10_000 {
            let now = monotonic_ns();
            assert!(now >= last);
            last = now;
        }
    }

    #[test]
    fn a_sleep_lasts_until_its_deadline_and_a_past_one_returns_at_once() {
        let deadline = monotonic_ns() + 2_000_000;
        sleep_until(deadline);
        assert!(monotonic_ns() >= deadline);
        let before = monotonic_ns();
        sleep_until(before.saturating_sub(1_000_000_000));
        // A deadline in the past does not sleep (a generous bound for a loaded machine).
        assert!(monotonic_ns() - before < 500_000_000);
    }
}
