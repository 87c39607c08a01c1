//! The filter's recent past, for measurements that describe an earlier instant than the IMU stream
//! has reached: a GNSS receiver outputs its fix some 50–200 ms after the instant it measured.
//! Compared with the present state, a fix would read the vehicle's motion over that delay as an
//! error (2 m at 10 m/s and 0.2 s); compared with the state of its own instant, it does not.
//!
//! The history keeps the nominal state about every millisecond. A state remembered from before a
//! correction lacks that correction; rather than rewrite every entry on every update, each entry
//! keeps the filter's [`CorrectionTotals`] of its time, and a past state is corrected on the way
//! out by what was injected since: a position correction δp moves it by δp, a velocity correction
//! δv made τ seconds after it moves it by δv·(−τ) in position (the error it corrected was smaller
//! by that much then) and by δv in velocity.

use std::collections::VecDeque;

use nalgebra::{UnitQuaternion, Vector3};

use crate::ekf::{CorrectionTotals, ErrorStateEkf};
use rins_earth::LocalOrigin;

/// Entries kept: with one per millisecond, a second of history, beyond any receiver latency.
pub const CAPACITY: usize = 1024;

/// Entries closer than this are not kept (the IMU may run at several kHz), µs.
const MIN_SPACING_US: u64 = 1_000;

/// One remembered instant.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Entry {
    t_us: u64,
    state: PastState,
    totals: CorrectionTotals,
}

/// The filter's state at a past instant, corrected by what was injected since.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PastState {
    /// Latitude, rad.
    pub lat: f64,
    /// Longitude, rad.
    pub lon: f64,
    /// Altitude, m.
    pub alt: f64,
    /// Velocity NED, m/s.
    pub velocity_ned: Vector3<f64>,
    /// Body → NED attitude.
    pub attitude: UnitQuaternion<f64>,
    /// Bias-corrected body rate, rad/s (for the lever arm's velocity).
    pub rate_body: Vector3<f64>,
}

impl PastState {
    /// The present state of `ekf` with body rate `rate_body` (no history needed).
    pub fn now(ekf: &ErrorStateEkf, rate_body: Vector3<f64>) -> Self {
        let s = ekf.state();
        Self {
            lat: s.lat,
            lon: s.lon,
            alt: s.alt,
            velocity_ned: s.velocity_ned,
            attitude: s.attitude,
            rate_body,
        }
    }

    /// `to − self` in local NED metres at this state's position.
    pub fn ned_to(&self, lat: f64, lon: f64, alt: f64) -> Vector3<f64> {
        Vector3::from(LocalOrigin::new(self.lat, self.lon, self.alt).ned(lat, lon, alt))
    }

    /// This state moved by `d` NED metres (the rest unchanged).
    fn moved(&self, d: Vector3<f64>) -> Self {
        let [lat, lon, alt] = LocalOrigin::new(self.lat, self.lon, self.alt).geodetic(d.into());
        Self {
            lat,
            lon,
            alt,
            ..*self
        }
    }
}

/// Why no past state was given.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HistoryError {
    /// Nothing remembered yet.
    Empty,
    /// The instant is older than the oldest entry.
    TooOld,
}

/// The last second of nominal states.
#[derive(Debug, Clone)]
pub struct StateHistory {
    entries: VecDeque<Entry>,
}

impl Default for StateHistory {
    fn default() -> Self {
        Self {
            entries: VecDeque::with_capacity(CAPACITY),
        }
    }
}

impl StateHistory {
    /// Forgets everything (a new solution starts).
    pub fn clear(&mut self) {
        self.entries.clear();
    }

    /// Remembers the filter's state at device time `t_us` (after its IMU sample), with the body
    /// rate of that sample. Skipped within a millisecond of the last entry or when time went
    /// backwards; the oldest entry goes when full.
    pub fn record(&mut self, t_us: u64, ekf: &ErrorStateEkf, rate_body: Vector3<f64>) {
        if self
            .entries
            .back()
            .is_some_and(|last| t_us < last.t_us.saturating_add(MIN_SPACING_US))
        {
            return;
        }
        if self.entries.len() == CAPACITY {
            self.entries.pop_front();
        }
        self.entries.push_back(Entry {
            t_us,
            state: PastState::now(ekf, rate_body),
            totals: *ekf.corrections(),
        });
    }

    /// The state at device time `t_us`, corrected by what `now` (the filter's present totals)
    /// holds beyond the entry's: interpolated between the two entries around it, or the newest
    /// moved on at its velocity when `t_us` is newer than every entry.
    pub fn at(&self, t_us: u64, now: &CorrectionTotals) -> Result<PastState, HistoryError> {
        let (Some(first), Some(last)) = (self.entries.front(), self.entries.back()) else {
            return Err(HistoryError::Empty);
        };
        if t_us < first.t_us {
            return Err(HistoryError::TooOld);
        }
        let entry = if t_us >= last.t_us {
            extrapolate(last, (t_us - last.t_us) as f64 * 1e-6)
        } else {
            let i = self.entries.partition_point(|e| e.t_us <= t_us);
            // `first.t_us <= t_us < last.t_us`: 1 <= i < len.
            let (a, b) = (&self.entries[i - 1], &self.entries[i]);
            let w = (t_us - a.t_us) as f64 / (b.t_us - a.t_us) as f64;
            interpolate(a, b, w)
        };
        Ok(corrected(&entry, now))
    }

    /// Entries held.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    /// Whether nothing is held.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

/// `a` moved on by `dt_s` at its velocity (north/east into latitude/longitude).
fn extrapolate(a: &Entry, dt_s: f64) -> Entry {
    Entry {
        state: a.state.moved(a.state.velocity_ned * dt_s),
        totals: CorrectionTotals {
            elapsed_s: a.totals.elapsed_s + dt_s,
            ..a.totals
        },
        ..*a
    }
}

/// The linear blend `a + w (b − a)` of two entries (attitude by slerp, totals from `a`: a
/// correction between them is rare and its share is below the interpolation's own error).
fn interpolate(a: &Entry, b: &Entry, w: f64) -> Entry {
    let lerp = |x: f64, y: f64| x + w * (y - x);
    let (sa, sb) = (&a.state, &b.state);
    Entry {
        t_us: a.t_us,
        state: PastState {
            lat: lerp(sa.lat, sb.lat),
            lon: sa.lon + w * crate::attitude::wrap_pi(sb.lon - sa.lon),
            alt: lerp(sa.alt, sb.alt),
            velocity_ned: sa.velocity_ned.lerp(&sb.velocity_ned, w),
            attitude: sa.attitude.slerp(&sb.attitude, w),
            rate_body: sa.rate_body.lerp(&sb.rate_body, w),
        },
        totals: CorrectionTotals {
            elapsed_s: lerp(a.totals.elapsed_s, b.totals.elapsed_s),
            ..a.totals
        },
    }
}

/// `e` with the corrections made after it: see the module documentation.
fn corrected(e: &Entry, now: &CorrectionTotals) -> PastState {
    let then = &e.totals;
    let dv = now.velocity_ned_mps - then.velocity_ned_mps;
    let dp = (now.position_ned_m - then.position_ned_m)
        - ((now.velocity_time - then.velocity_time) - dv * then.elapsed_s);
    let moved = e.state.moved(dp);
    PastState {
        velocity_ned: moved.velocity_ned + dv,
        ..moved
    }
}
