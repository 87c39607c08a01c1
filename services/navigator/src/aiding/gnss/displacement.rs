//! A drift test that does not go through the filter's gain: the receiver's displacement against
//! the velocity over the same time.
//!
//! The innovation test ([`crate::aiding::gnss::monitor`]) sees a slow drift only through what the filter
//! has not yet followed. How much the filter follows depends on its covariance, and so on the
//! phase of flight: a 0.5 m/s drift starting 31 or 45 s into the simulated flight went unseen
//! for 40 s. This test instead sums, between consecutive fixes, the receiver's horizontal
//! displacement less the velocity integrated over the interval (trapezoid, at the fixes' own
//! instants). A receiver whose position agrees with the velocity keeps that offset constant but
//! for its noise; one walked away at v m/s moves it at v m/s, whatever the filter does. The mean
//! offset over the last [`BLOCK_S`] is compared with the mean over a block [`WINDOW_S`] earlier:
//! the difference over its σ for white fix noise of the reported accuracy,
//! `σ_h √(1/n₁ + 1/n₂)`, is the statistic.
//!
//! The velocity is the receiver's own where it reports one (Doppler-derived, which a spoofer that
//! walks the position does not move with it), else the solution's. The solution's velocity was
//! tried first: on the real quadrotor flights, with fixes made from the RTK reference, it raised
//! 8 alarms in 12 fused runs (its error over 10 s reaches the 6 σ of the test), where the
//! receiver's velocity raised none.
//!
//! Fixed size, no allocation.

use std::collections::VecDeque;

use nalgebra::Vector3;
use rins_earth::wgs84::{meridian_radius, prime_vertical_radius};

use crate::attitude::wrap_pi;

/// Time between the two blocks compared, s.
pub const WINDOW_S: f64 = 10.0;
/// Length of each block, s.
pub const BLOCK_S: f64 = 2.0;
/// A gap between fixes longer than this starts the test again, s.
const MAX_GAP_S: f64 = 1.0;
/// Offsets remembered: [`WINDOW_S`] + [`BLOCK_S`] at up to 10 Hz, with room.
const CAPACITY: usize = 160;
/// Fixes each block needs before the test judges: one, so that a 1 Hz receiver is judged too.
const MIN_FIXES_PER_BLOCK: usize = 1;

#[derive(Debug, Clone, Copy)]
struct Previous {
    t_us: u64,
    lat: f64,
    lon: f64,
    velocity_ne: [f64; 2],
}

/// The offset between the receiver's track and the inertial one, over the last seconds.
#[derive(Debug, Clone)]
pub struct DisplacementTest {
    previous: Option<Previous>,
    offset_m: [f64; 2],
    /// (device time µs, offset north/east m), oldest first; allocated once, at its capacity.
    offsets: VecDeque<(u64, [f64; 2])>,
}

impl Default for DisplacementTest {
    fn default() -> Self {
        Self {
            previous: None,
            offset_m: [0.0; 2],
            offsets: VecDeque::with_capacity(CAPACITY),
        }
    }
}

impl DisplacementTest {
    /// Forgets everything: after an outage, a rejection, a re-admission or a re-set.
    pub fn reset(&mut self) {
        self.previous = None;
        self.offset_m = [0.0; 2];
        self.offsets.clear();
    }

    /// Takes the fix at device time `t_us` at geodetic `position` (rad, rad, m) with the
    /// solution's velocity at that instant, `velocity_ned` (m/s), and the fix's horizontal σ per
    /// axis `sigma_h_m`. Returns the statistic (σ units, 2 dof) once both blocks hold fixes.
    pub fn push(
        &mut self,
        t_us: u64,
        position: [f64; 3],
        velocity_ned: &Vector3<f64>,
        sigma_h_m: f64,
    ) -> Option<f64> {
        let [lat, lon, alt] = position;
        let velocity_ne = [velocity_ned.x, velocity_ned.y];
        let finite = lat.is_finite() && lon.is_finite() && alt.is_finite();
        if !finite || !velocity_ne.iter().all(|v| v.is_finite()) {
            return None;
        }
        match self.previous {
            Some(p) if t_us > p.t_us && (t_us - p.t_us) as f64 * 1e-6 <= MAX_GAP_S => {
                let dt = (t_us - p.t_us) as f64 * 1e-6;
                let north = (lat - p.lat) * (meridian_radius(lat) + alt);
                let east = wrap_pi(lon - p.lon) * (prime_vertical_radius(lat) + alt) * lat.cos();
                for (k, moved) in [north, east].into_iter().enumerate() {
                    self.offset_m[k] += moved - 0.5 * (velocity_ne[k] + p.velocity_ne[k]) * dt;
                }
            }
            _ => self.reset(),
        }
        self.previous = Some(Previous {
            t_us,
            lat,
            lon,
            velocity_ne,
        });
        if self.offsets.len() == CAPACITY {
            self.offsets.pop_front();
        }
        self.offsets.push_back((t_us, self.offset_m));
        self.statistic(t_us, sigma_h_m)
    }

    /// Mean offset and count of the entries with `from_s <= t_now − t < to_s`.
    fn block(&self, t_now_us: u64, from_s: f64, to_s: f64) -> ([f64; 2], usize) {
        let (mut sum, mut n) = ([0.0; 2], 0usize);
        for (t, offset) in &self.offsets {
            let age_s = t_now_us.saturating_sub(*t) as f64 * 1e-6;
            if age_s >= from_s && age_s < to_s {
                sum[0] += offset[0];
                sum[1] += offset[1];
                n += 1;
            }
        }
        if n == 0 {
            return ([0.0; 2], 0);
        }
        ([sum[0] / n as f64, sum[1] / n as f64], n)
    }

    fn statistic(&self, t_now_us: u64, sigma_h_m: f64) -> Option<f64> {
        let (recent, n1) = self.block(t_now_us, 0.0, BLOCK_S);
        let (earlier, n2) = self.block(t_now_us, WINDOW_S, WINDOW_S + BLOCK_S);
        if n1 < MIN_FIXES_PER_BLOCK
            || n2 < MIN_FIXES_PER_BLOCK
            || sigma_h_m.is_nan()
            || sigma_h_m <= 0.0
        {
            return None;
        }
        let sigma = sigma_h_m * (1.0 / n1 as f64 + 1.0 / n2 as f64).sqrt();
        let d = [recent[0] - earlier[0], recent[1] - earlier[1]];
        Some(d[0].hypot(d[1]) / sigma)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LAT: f64 = 0.8;
    const ALT: f64 = 500.0;

    /// A vehicle at `speed` m/s east, fixes at 5 Hz for `seconds`; the receiver's position walks
    /// north at `drift` m/s from `drift_from_s` and carries a deterministic ±`noise` m pattern.
    fn run(speed: f64, drift: f64, drift_from_s: f64, noise: f64, seconds: f64) -> Vec<f64> {
        let mut test = DisplacementTest::default();
        let r_n = meridian_radius(LAT) + ALT;
        let r_e = (prime_vertical_radius(LAT) + ALT) * LAT.cos();
        let mut out = Vec::new();
        let n = (seconds * 5.0) as usize;
        for k in 0..n {
            let t = k as f64 * 0.2;
            let walk = drift * (t - drift_from_s).max(0.0);
            let wiggle = noise * if k % 2 == 0 { 1.0 } else { -1.0 };
            let north = walk + wiggle;
            let east = speed * t - wiggle;
            let position = [LAT + north / r_n, 0.1 + east / r_e, ALT];
            let v = Vector3::new(0.0, speed, 0.0);
            out.push(
                test.push((t * 1e6) as u64 + 1, position, &v, 1.5)
                    .unwrap_or(0.0),
            );
        }
        out
    }

    #[test]
    fn a_receiver_that_agrees_with_the_inertial_velocity_stays_near_zero() {
        let stats = run(20.0, 0.0, 0.0, 1.5, 60.0);
        // The ±1.5 m pattern cancels in blocks of even length and leaves at most one fix's worth
        // in the others (and in the first, part-filled ones): well under the 6 σ threshold.
        let max = stats.iter().copied().fold(0.0, f64::max);
        assert!(max < 2.0, "{max}");
    }

    #[test]
    fn a_drift_of_half_a_metre_a_second_passes_six_sigma_within_fifteen_seconds() {
        let stats = run(20.0, 0.5, 20.0, 1.5, 60.0);
        let first = stats.iter().position(|&s| s > 6.0).expect("never fired");
        let after_s = first as f64 * 0.2 - 20.0;
        assert!((0.0..=15.0).contains(&after_s), "fired {after_s} s after");
        // The blocks' means: 0.5 m/s over 10 s is 5 m against σ 1.5·√(2/10) = 0.67 m.
        let last = stats.last().copied().unwrap_or(0.0);
        assert!((last - 5.0 / 0.67).abs() < 0.5, "{last}");
    }

    #[test]
    fn a_gap_starts_again_and_nothing_is_judged_before_both_blocks_fill() {
        let mut test = DisplacementTest::default();
        let v = Vector3::zeros();
        for k in 0..50u64 {
            assert_eq!(test.push(k * 200_000 + 1, [LAT, 0.1, ALT], &v, 1.5), None);
        }
        assert!(
            test.push(50 * 200_000 + 1, [LAT, 0.1, ALT], &v, 1.5)
                .is_some()
        );
        // Five seconds without a fix.
        assert_eq!(test.push(80 * 200_000, [LAT, 0.1, ALT], &v, 1.5), None);
        assert_eq!(test.push(81 * 200_000, [f64::NAN, 0.1, ALT], &v, 1.5), None);
    }
}
