//! Whether the serial device is there, as the reading loop sees it: since when it is away, how
//! many reopen attempts it took, how many times it came back. Pure (the caller passes the clock and
//! does the logging), so that the decisions are tested without a device: an absent device is
//! logged once per episode rather than at every retry, and only a device that came back after
//! working counts as a reconnect.

use std::time::Duration;

use crate::backoff::Backoff;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Not opened yet since start-up; `since_ns` is the first failed attempt.
    NotYetOpened { since_ns: Option<u64> },
    /// Open; `data_seen` once a read returned bytes.
    Open { data_seen: bool },
    /// Lost at `since_ns`, not reopened yet.
    Away { since_ns: u64 },
}

/// What the caller does about a failed attempt to open the device.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Retry {
    /// Wait this long before the next attempt.
    pub delay: Duration,
    /// The first failure of this episode: log it (later ones are expected and not worth a line).
    pub first: bool,
}

/// What an open after an absence means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Opened {
    /// The first open since start-up, after `waited` and `attempts` failed attempts.
    First {
        /// Time since start-up.
        waited: Duration,
        /// Failed attempts before this one.
        attempts: u32,
    },
    /// The device is back after being `away` for `attempts` failed attempts.
    Reconnected {
        /// Time the device was missing.
        away: Duration,
        /// Failed attempts before this one.
        attempts: u32,
    },
}

/// Whether the device is open, and since when it is missing: what the log says of each open and loss.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Presence {
    backoff: Backoff,
    state: State,
    /// Attempts that failed in the current episode.
    failures: u32,
    reconnects: u64,
}

fn since(start_ns: u64, now_ns: u64) -> Duration {
    Duration::from_nanos(now_ns.saturating_sub(start_ns))
}

impl Presence {
    /// A device not opened yet, retried with `backoff`.
    pub fn new(backoff: Backoff) -> Self {
        Self {
            backoff,
            state: State::NotYetOpened { since_ns: None },
            failures: 0,
            reconnects: 0,
        }
    }

    /// An attempt to open the device failed at `now_ns`.
    pub fn open_failed(&mut self, now_ns: u64) -> Retry {
        let first = match self.state {
            State::NotYetOpened { since_ns: None } => {
                self.state = State::NotYetOpened {
                    since_ns: Some(now_ns),
                };
                true
            }
            State::NotYetOpened { since_ns: Some(_) } | State::Away { .. } => false,
            // Not reported lost first: this failure starts the episode.
            State::Open { .. } => {
                self.state = State::Away { since_ns: now_ns };
                true
            }
        };
        self.failures = self.failures.saturating_add(1);
        Retry {
            delay: self.backoff.next_delay(),
            first,
        }
    }

    /// The open device stopped working (hang-up, end of file, I/O error) at `now_ns`. Returns the
    /// delay before the first attempt to reopen it.
    pub fn lost(&mut self, now_ns: u64) -> Duration {
        if let State::Open { data_seen } = self.state {
            // A device that delivered data worked: its absence starts with the shortest delay.
            // One that hung up before sending anything keeps backing off (a flapping port).
            if data_seen {
                self.backoff.reset();
            }
            self.state = State::Away { since_ns: now_ns };
            self.failures = 0;
        }
        self.backoff.next_delay()
    }

    /// The device opened at `now_ns`.
    pub fn opened(&mut self, now_ns: u64) -> Opened {
        let attempts = self.failures;
        let opened = match self.state {
            State::Away { since_ns } => {
                self.reconnects += 1;
                Opened::Reconnected {
                    away: since(since_ns, now_ns),
                    attempts,
                }
            }
            State::NotYetOpened { since_ns } => Opened::First {
                waited: since_ns.map_or(Duration::ZERO, |s| since(s, now_ns)),
                attempts,
            },
            State::Open { .. } => Opened::First {
                waited: Duration::ZERO,
                attempts,
            },
        };
        self.state = State::Open { data_seen: false };
        self.failures = 0;
        opened
    }

    /// A read returned bytes: the device works. Cheap enough for every read.
    pub fn data_arrived(&mut self) {
        if self.state == (State::Open { data_seen: false }) {
            self.state = State::Open { data_seen: true };
        }
    }

    /// Times the device came back after being lost.
    pub fn reconnects(&self) -> u64 {
        self.reconnects
    }

    /// The backoff between attempts to open the device.
    pub fn backoff(&self) -> &Backoff {
        &self.backoff
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MS: fn(u64) -> Duration = Duration::from_millis;
    const NS_PER_MS: u64 = 1_000_000;

    fn presence() -> Presence {
        Presence::new(Backoff::new(MS(10), MS(1000)))
    }

    #[test]
    fn a_late_device_is_waited_for_with_backoff_and_logged_once() {
        let mut p = presence();
        let first = p.open_failed(0);
        assert_eq!(
            first,
            Retry {
                delay: MS(10),
                first: true
            }
        );
        assert_eq!(
            p.open_failed(10 * NS_PER_MS),
            Retry {
                delay: MS(20),
                first: false
            }
        );
        assert_eq!(p.open_failed(30 * NS_PER_MS).delay, MS(40));
        assert_eq!(
            p.opened(70 * NS_PER_MS),
            Opened::First {
                waited: MS(70),
                attempts: 3
            }
        );
        assert_eq!(p.reconnects(), 0, "a late device is no reconnect");
        let mut q = presence();
        assert_eq!(
            q.opened(5),
            Opened::First {
                waited: MS(0),
                attempts: 0
            }
        );
    }

    #[test]
    fn a_lost_device_is_counted_once_when_back_and_backoff_restarts_after_data() {
        let mut p = presence();
        p.opened(0);
        p.data_arrived();
        assert_eq!(p.lost(1000 * NS_PER_MS), MS(10));
        // The path is gone: further attempts fail quietly with growing delays.
        let delays: Vec<Duration> = (0..3)
            .map(|i| {
                let r = p.open_failed((1010 + i) * NS_PER_MS);
                assert!(!r.first);
                r.delay
            })
            .collect();
        assert_eq!(delays, [MS(20), MS(40), MS(80)]);
        assert_eq!(
            p.opened(2270 * NS_PER_MS),
            Opened::Reconnected {
                away: MS(1270),
                attempts: 3
            }
        );
        assert_eq!(p.reconnects(), 1);
        // It worked again: the next loss starts from the shortest delay.
        p.data_arrived();
        assert_eq!(p.lost(3000 * NS_PER_MS), MS(10));
        assert!(matches!(
            p.opened(3010 * NS_PER_MS),
            Opened::Reconnected { attempts: 0, .. }
        ));
        assert_eq!(p.reconnects(), 2);
    }

    #[test]
    fn a_port_that_hangs_up_before_any_data_keeps_backing_off() {
        let mut p = presence();
        p.opened(0);
        assert_eq!(p.lost(1), MS(10));
        p.opened(2);
        assert_eq!(p.lost(3), MS(20));
        p.opened(4);
        assert_eq!(p.lost(5), MS(40));
        assert_eq!(p.reconnects(), 2);
        // An open failure while it was open starts an episode of its own, logged.
        p.opened(6);
        assert!(p.open_failed(7).first);
        assert_eq!(p.backoff().max(), MS(1000));
    }
}
