//! Applying the aiding readings at a fixed place in the IMU stream, whatever the order in which
//! the processes delivered them. A reading arrives on its own topic, a hop or two apart from the
//! fused IMU sample of the same instant; applied on arrival, it would meet the filter after a
//! number of IMU samples that depends on scheduling, and two navigator lanes (or a replay of a
//! recording) would differ. Held until the IMU stream is a fixed time past the reading's place,
//! then applied in order, it meets the same filter state every time — as long as it arrived within
//! the hold, which it does with milliseconds to spare; a reading that comes later is applied at
//! the next release and counted.
//!
//! One hold serves every source; each says where its readings sit on which time base (the device
//! time of a baro or magnetometer reading, the receive time of a GNSS fix, see [`Held`]), how
//! long they are held and how many at most.

use std::collections::VecDeque;

/// How far the IMU stream must be past a reading before it is applied, µs: well beyond the few
/// tens of µs the aiding paths take on a loaded two-core computer, and short against the time the
/// filter takes to move (at 30 °/s, 0.3° of heading; at 2 m/s climb, 2 cm).
pub const HOLD_US: u64 = 10_000;

/// A reading that waits in a [`Hold`].
pub trait Held {
    /// Its place in the stream: the time on the hold's time base, then its rank among readings
    /// of the same time (lower first).
    fn place(&self) -> (u64, u8);
}

/// Readings waiting for the IMU stream to pass them, in order of their place.
#[derive(Debug, Clone)]
pub struct Hold<T> {
    held: VecDeque<T>,
    /// How far the stream must be past a reading's place to release it, in the time base's units.
    after: u64,
    capacity: usize,
    /// The stream's time at the last release.
    now: Option<u64>,
    late: u64,
    displaced: u64,
}

impl<T: Held> Hold<T> {
    /// An empty hold that releases a reading once the stream is `after` past its place and holds
    /// `capacity` readings at most. Allocates its storage now, never per reading.
    pub fn new(after: u64, capacity: usize) -> Self {
        Self {
            held: VecDeque::with_capacity(capacity),
            after,
            capacity,
            now: None,
            late: 0,
            displaced: 0,
        }
    }

    /// Holds `item` among the held readings in order of place. When the hold is full its oldest
    /// reading is taken out, counted, and returned: the caller applies it at once or drops it.
    pub fn push(&mut self, item: T) -> Option<T> {
        let key = item.place();
        if self
            .now
            .is_some_and(|now| key.0.saturating_add(self.after) <= now)
        {
            // Its place in the stream has passed: it arrived later than the hold allows.
            self.late += 1;
        }
        let displaced = if self.held.len() == self.capacity {
            self.held.pop_front()
        } else {
            None
        };
        if displaced.is_some() {
            self.displaced += 1;
        }
        let at = self
            .held
            .iter()
            .rposition(|h| h.place() <= key)
            .map_or(0, |i| i + 1);
        self.held.insert(at, item);
        displaced
    }

    /// Hands `apply`, oldest first, every reading the stream at time `now` has passed by the hold
    /// (and every late one).
    pub fn release(&mut self, now: u64, mut apply: impl FnMut(T)) {
        self.now = Some(now);
        while let Some(front) = self.held.front() {
            if front.place().0.saturating_add(self.after) > now {
                break;
            }
            if let Some(item) = self.held.pop_front() {
                apply(item);
            }
        }
    }

    /// Readings that arrived after their place in the stream had passed.
    pub fn late(&self) -> u64 {
        self.late
    }

    /// Readings taken out of a full hold (the IMU stream stopped while aiding went on).
    pub fn displaced(&self) -> u64 {
        self.displaced
    }

    /// Readings held now.
    pub fn len(&self) -> usize {
        self.held.len()
    }

    /// Whether none is held.
    pub fn is_empty(&self) -> bool {
        self.held.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reading of time `t` and rank `rank`, told apart by `id`.
    #[derive(Debug, Clone, Copy, PartialEq)]
    struct R {
        t: u64,
        rank: u8,
        id: u32,
    }

    impl Held for R {
        fn place(&self) -> (u64, u8) {
            (self.t, self.rank)
        }
    }

    const fn r(t: u64, rank: u8, id: u32) -> R {
        R { t, rank, id }
    }

    /// The readings released at each stream time, for one arrival order.
    fn schedule(arrivals: &[(u64, Vec<R>)], stream: &[u64]) -> Vec<(u64, Vec<R>)> {
        let mut hold = Hold::new(HOLD_US, 256);
        let mut out = Vec::new();
        for &t in stream {
            for (at, readings) in arrivals {
                if *at == t {
                    for x in readings {
                        assert_eq!(hold.push(*x), None);
                    }
                }
            }
            let mut released = Vec::new();
            hold.release(t, |x| released.push(x));
            out.push((t, released));
        }
        out
    }

    #[test]
    fn arrival_order_does_not_change_where_readings_are_released() {
        let stream: Vec<u64> = (0..40).map(|i| i * 1_000).collect();
        // Readings of 3 ms and 5 ms, delivered early in one run, late (within the hold) and in
        // the other order in another.
        let early = [
            (3_000, vec![r(3_000, 0, 1), r(3_000, 1, 2)]),
            (5_000, vec![r(5_000, 1, 3)]),
        ];
        let late = [
            (9_000, vec![r(5_000, 1, 3), r(3_000, 1, 2)]),
            (12_000, vec![r(3_000, 0, 1)]),
        ];
        let a = schedule(&early, &stream);
        assert_eq!(a, schedule(&late, &stream));
        // Released at the first stream time a hold past each, lower rank first.
        let at = |t: u64| a.iter().find(|(s, _)| *s == t).map(|(_, x)| x.clone());
        assert_eq!(at(13_000), Some(vec![r(3_000, 0, 1), r(3_000, 1, 2)]));
        assert_eq!(at(15_000), Some(vec![r(5_000, 1, 3)]));
        assert_eq!(a.iter().map(|(_, x)| x.len()).sum::<usize>(), 3);
    }

    #[test]
    fn a_reading_later_than_the_hold_is_released_next_and_counted() {
        let mut hold = Hold::new(HOLD_US, 4);
        hold.release(50_000, |_| panic!("nothing held"));
        assert_eq!(hold.push(r(1_000, 0, 1)), None);
        assert_eq!(hold.late(), 1);
        let mut released = Vec::new();
        hold.release(51_000, |x| released.push(x));
        assert_eq!(released, [r(1_000, 0, 1)]);
        assert!(hold.is_empty());
    }

    #[test]
    fn a_full_hold_hands_back_its_oldest_and_counts_it() {
        let capacity = 8;
        let mut hold = Hold::new(HOLD_US, capacity);
        let mut displaced = Vec::new();
        for i in 0..(capacity as u32 + 2) {
            displaced.extend(hold.push(r(u64::from(i), 0, i)));
        }
        assert_eq!(displaced, [r(0, 0, 0), r(1, 0, 1)]);
        assert_eq!(hold.displaced(), 2);
        assert_eq!(hold.len(), capacity);
    }
}
