//! Applying the aiding readings at a fixed place in the IMU stream, whatever the order in which
//! the processes delivered them. A barometric height or a magnetometer sample arrives on its own
//! topic, a hop or two apart from the fused IMU sample of the same serial frame; applied on
//! arrival, it would meet the filter after a number of IMU samples that depends on scheduling, and
//! two navigator lanes (or a replay of a recording) would differ. Held until the IMU stream is
//! [`HOLD_US`] past the reading's device time, then applied in device-time order, it meets the
//! same filter state every time — as long as it arrived within the hold, which it does with
//! milliseconds to spare; a reading that comes later is applied at once and counted.

use std::collections::VecDeque;

use ipc_types::{Altitude, RawMag};

use crate::navigator::Navigator;

/// How far the IMU stream must be past a reading's device time before it is applied, µs: well
/// beyond the few tens of µs the aiding paths take on a loaded two-core computer, and short
/// against the time the filter takes to move (at 30 °/s, 0.3° of heading; at 2 m/s climb, 2 cm).
pub const HOLD_US: u64 = 10_000;

/// Readings held at most; beyond it the oldest is applied at once (the IMU stream stopped while
/// aiding went on).
const CAPACITY: usize = 256;

/// One aiding reading.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Reading {
    /// A barometric height: device time µs, height m, variance m², valid.
    Baro {
        /// Device time, µs.
        t_us: u64,
        /// Height above mean sea level, m.
        height_m: f64,
        /// Its variance, m².
        variance_m2: f64,
        /// The altimeter's validity flag.
        valid: bool,
    },
    /// A magnetometer sample: device time µs, field µT (body FRD, raw).
    Mag {
        /// Device time, µs.
        t_us: u64,
        /// Raw field, µT.
        field_ut: [f64; 3],
    },
}

impl Reading {
    /// The altimeter's height.
    pub fn from_altitude(alt: &Altitude) -> Self {
        Self::Baro {
            t_us: alt.header.origin_device_time_us,
            height_m: alt.height_m,
            variance_m2: alt.height_var,
            valid: alt.valid != 0,
        }
    }

    /// A raw magnetometer sample.
    pub fn from_mag(mag: &RawMag) -> Self {
        Self::Mag {
            t_us: mag.header.origin_device_time_us,
            field_ut: mag.field_ut.map(f64::from),
        }
    }

    /// Hands the reading to the filter.
    pub fn apply(self, nav: &mut Navigator) {
        let _ = match self {
            Self::Baro {
                t_us,
                height_m,
                variance_m2,
                valid,
            } => nav.on_baro(t_us, height_m, variance_m2, valid),
            Self::Mag { t_us, field_ut } => nav.on_mag(t_us, field_ut),
        };
    }

    /// Device time, µs.
    pub fn t_us(&self) -> u64 {
        match self {
            Self::Baro { t_us, .. } | Self::Mag { t_us, .. } => *t_us,
        }
    }

    /// Order of readings of the same device time: baro before mag.
    fn rank(&self) -> u8 {
        match self {
            Self::Baro { .. } => 0,
            Self::Mag { .. } => 1,
        }
    }
}

/// The readings waiting for the IMU stream to pass them.
#[derive(Debug, Clone)]
pub struct AidingQueue {
    held: VecDeque<Reading>,
    /// Device time of the last IMU sample the queue was released for.
    imu_t_us: Option<u64>,
    late: u64,
}

impl Default for AidingQueue {
    fn default() -> Self {
        Self {
            held: VecDeque::with_capacity(CAPACITY),
            imu_t_us: None,
            late: 0,
        }
    }
}

impl AidingQueue {
    /// Holds `r`, in device-time order among the held readings; `apply` takes the oldest when the
    /// queue is full.
    pub fn push(&mut self, r: Reading, apply: impl FnMut(Reading)) {
        if self
            .imu_t_us
            .is_some_and(|imu| r.t_us().saturating_add(HOLD_US) <= imu)
        {
            // Its place in the stream has passed: it arrived later than the hold allows.
            self.late += 1;
        }
        if self.held.len() == CAPACITY
            && let Some(oldest) = self.held.pop_front()
        {
            let mut apply = apply;
            apply(oldest);
        }
        let key = (r.t_us(), r.rank());
        let at = self
            .held
            .iter()
            .rposition(|h| (h.t_us(), h.rank()) <= key)
            .map_or(0, |i| i + 1);
        self.held.insert(at, r);
    }

    /// Applies, oldest first, every reading the IMU sample at `imu_t_us` has passed by the hold
    /// (and every late one).
    pub fn release(&mut self, imu_t_us: u64, mut apply: impl FnMut(Reading)) {
        self.imu_t_us = Some(imu_t_us);
        while let Some(front) = self.held.front() {
            if front.t_us().saturating_add(HOLD_US) > imu_t_us {
                break;
            }
            if let Some(r) = self.held.pop_front() {
                apply(r);
            }
        }
    }

    /// [`AidingQueue::push`] for the navigator `nav`.
    pub fn hold(&mut self, r: Reading, nav: &mut Navigator) {
        self.push(r, |r| r.apply(nav));
    }

    /// [`AidingQueue::release`] into the navigator `nav`, before its IMU sample at `imu_t_us`.
    pub fn release_to(&mut self, imu_t_us: u64, nav: &mut Navigator) {
        self.release(imu_t_us, |r| r.apply(nav));
    }

    /// Readings that arrived after their place in the IMU stream had passed.
    pub fn late(&self) -> u64 {
        self.late
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

    fn baro(t_us: u64) -> Reading {
        Reading::Baro {
            t_us,
            height_m: t_us as f64,
            variance_m2: 1.0,
            valid: true,
        }
    }

    fn mag(t_us: u64) -> Reading {
        Reading::Mag {
            t_us,
            field_ut: [t_us as f64, 0.0, 0.0],
        }
    }

    /// The readings applied before each IMU sample, for one arrival order.
    fn schedule(arrivals: &[(u64, Vec<Reading>)], imu: &[u64]) -> Vec<(u64, Vec<Reading>)> {
        let mut q = AidingQueue::default();
        let mut out = Vec::new();
        for &t in imu {
            for (at, readings) in arrivals {
                if *at == t {
                    for r in readings {
                        q.push(*r, |_| panic!("not full"));
                    }
                }
            }
            let mut applied = Vec::new();
            q.release(t, |r| applied.push(r));
            out.push((t, applied));
        }
        out
    }

    #[test]
    fn arrival_order_does_not_change_where_readings_apply() {
        let imu: Vec<u64> = (0..40).map(|i| i * 1_000).collect();
        // Readings of 3 ms and 5 ms, delivered early in one run, late (within the hold) and
        // in the other order in another.
        let early = [
            (3_000, vec![baro(3_000), mag(3_000)]),
            (5_000, vec![mag(5_000)]),
        ];
        let late = [
            (9_000, vec![mag(5_000), mag(3_000)]),
            (12_000, vec![baro(3_000)]),
        ];
        let a = schedule(&early, &imu);
        let b = schedule(&late, &imu);
        assert_eq!(a, b);
        // Applied at the first IMU sample 10 ms past each, baro before mag.
        let at = |t: u64| a.iter().find(|(s, _)| *s == t).map(|(_, r)| r.clone());
        assert_eq!(at(13_000), Some(vec![baro(3_000), mag(3_000)]));
        assert_eq!(at(15_000), Some(vec![mag(5_000)]));
        assert_eq!(a.iter().map(|(_, r)| r.len()).sum::<usize>(), 3);
    }

    #[test]
    fn a_reading_later_than_the_hold_is_applied_at_once_and_counted() {
        let mut q = AidingQueue::default();
        q.release(50_000, |_| panic!("nothing held"));
        q.push(baro(1_000), |_| panic!("not full"));
        assert_eq!(q.late(), 1);
        let mut applied = Vec::new();
        q.release(51_000, |r| applied.push(r));
        assert_eq!(applied, [baro(1_000)]);
        assert!(q.is_empty());
    }

    #[test]
    fn a_full_queue_applies_its_oldest() {
        let mut q = AidingQueue::default();
        let mut spilled = Vec::new();
        for i in 0..(CAPACITY as u64 + 2) {
            q.push(mag(i), |r| spilled.push(r));
        }
        assert_eq!(spilled, [mag(0), mag(1)]);
        assert_eq!(q.len(), CAPACITY);
    }
}
