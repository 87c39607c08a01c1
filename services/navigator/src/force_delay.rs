//! Rate and specific force measured at the same instant: a unit whose gyro channel lags its
//! accelerometer's (their anti-alias filters differ) pairs each rate sample with a specific force
//! taken that much earlier. The navigator delays the specific force by `[navigator] gyro_lag_s`
//! and integrates the pair, which describes the instant the force was measured: the solution is
//! published with the rate sample's time, the lag after that instant.
//!
//! On foot-mounted recordings of two different units the swing's height drifted 2–4 cm a stride
//! and the strides came out short; pairing the rate with the force of 5–10 ms earlier removed
//! most of both (`docs/foot-mounted.md`).

/// Largest `gyro_lag_s`, s.
pub const MAX_GYRO_LAG_S: f64 = 0.05;
/// Force samples kept: the lag reaches back at most this many samples (128 samples are 16 ms at
/// 8 kHz, 0.64 s at 200 Hz); a longer lag at a high rate is served by the oldest sample kept.
const CAPACITY: usize = 128;

/// The delay line of the specific force. Allocation-free.
#[derive(Debug, Clone)]
pub struct ForceDelay {
    lag_us: u64,
    ring: [(u64, [f64; 3]); CAPACITY],
    /// Next slot to write.
    head: usize,
    /// Samples held.
    len: usize,
}

impl ForceDelay {
    /// A delay of `lag_s` seconds (checked beforehand: finite, 0..=MAX_GYRO_LAG_S; anything else
    /// is no delay).
    pub fn new(lag_s: f64) -> Self {
        let lag_s = if (0.0..=MAX_GYRO_LAG_S).contains(&lag_s) {
            lag_s
        } else {
            0.0
        };
        Self {
            lag_us: (lag_s * 1e6).round() as u64,
            ring: [(0, [0.0; 3]); CAPACITY],
            head: 0,
            len: 0,
        }
    }

    /// Keeps `force`, taken at `t_us`, and returns the force kept whose time is nearest to
    /// `t_us − lag` (the oldest kept while none is that old, as at the start). Time going back
    /// starts the line over.
    pub fn push(&mut self, t_us: u64, force: [f64; 3]) -> [f64; 3] {
        if self.lag_us == 0 {
            return force;
        }
        let newest = (self.head + CAPACITY - 1) % CAPACITY;
        if self.len > 0 && t_us < self.ring[newest].0 {
            self.len = 0;
        }
        self.ring[self.head] = (t_us, force);
        self.head = (self.head + 1) % CAPACITY;
        self.len = (self.len + 1).min(CAPACITY);
        let target = t_us.saturating_sub(self.lag_us);
        let mut best = force;
        let mut best_distance = u64::MAX;
        for i in 0..self.len {
            let (t, f) = self.ring[(self.head + CAPACITY - 1 - i) % CAPACITY];
            let distance = t.abs_diff(target);
            if distance < best_distance {
                (best, best_distance) = (f, distance);
            }
            // Older samples only get farther from the target.
            if t <= target {
                break;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(k: u64) -> [f64; 3] {
        [k as f64, 0.0, 0.0]
    }

    #[test]
    fn the_force_of_the_lag_earlier_comes_back_and_no_lag_is_no_delay() {
        // 200 Hz, 10 ms: two samples back, with the timestamps jittering by 0.2 ms.
        let mut d = ForceDelay::new(0.010);
        let times = [0, 5_100, 9_900, 15_000, 20_200, 24_900];
        let out: Vec<f64> = times
            .iter()
            .enumerate()
            .map(|(k, &t)| d.push(t, at(k as u64))[0])
            .collect();
        // The first two have nothing that old: the oldest kept (sample 0).
        assert_eq!(out, vec![0.0, 0.0, 0.0, 1.0, 2.0, 3.0]);
        let mut none = ForceDelay::new(0.0);
        assert_eq!(none.push(7, at(3)), at(3));
        // Out of range is no delay.
        assert_eq!(ForceDelay::new(f64::NAN).push(7, at(4)), at(4));
    }

    #[test]
    fn time_going_back_starts_over() {
        let mut d = ForceDelay::new(0.005);
        for k in 0..10 {
            d.push(1_000_000 + k * 5_000, at(k));
        }
        assert_eq!(d.push(0, at(99)), at(99));
        assert_eq!(d.push(5_000, at(100)), at(99));
    }
}
