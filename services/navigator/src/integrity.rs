//! Integrity of the navigation solution: whether it can be used, judged from the filter's own
//! consistency and from its input, and published with every solution ([`ipc_types::Integrity`],
//! reasons in [`ipc_types::integrity_reason`]).
//!
//! **Invalid** — the solution must not be used:
//! - the fused IMU has had no usable sample for `imu_outage_s` (every channel of a type out, the
//!   block saturated, frames rejected upstream): the state is not being propagated;
//! - the device time has not advanced over `time_stall_samples` samples in a row: nothing is
//!   integrated although samples arrive;
//! - every configured aiding source that reports is persistently rejected (each update gated out
//!   for `rejection_persist_s`): nothing that observes the state agrees with it;
//! - the state is not finite.
//!
//! **Degraded** — usable with care:
//! - a shorter IMU outage, or a single device-time glitch;
//! - one aiding source rejected several times in a row, or its normalised innovation squared (NIS, d²/m
//!   over the last `nis_window` accepted updates) above `nis_limit` on average — a consistent
//!   filter has a mean of 1. Not for zero-velocity updates: they come on every sample of a stance,
//!   their innovations strongly correlated, their σ a tuning device rather than a sensor's noise;
//! - an error standard deviation beyond its limit (tilt, heading, vertical, horizontal);
//! - a configured aiding source silent (the filter coasts);
//! - recovering: after an invalid episode or a reset from an aiding source, until
//!   `recovery_s` has passed and every configured source that reports has been accepted again;
//! - a fault among the redundant IMU channels that fusion detects but cannot yet isolate; after
//!   its isolation while the attitude σ it widened is above `fault_attitude_sigma_deg`, and for
//!   good once the episode integrated more than that (see [`crate::unisolated_fault`]);
//! - no configured initial position and no absolute fix yet: the horizontal position is unknown.
//!
//! **Ok** otherwise. The monitor is allocation-free and works in device time, like the filter.

use ipc_types::{Integrity, integrity_reason as why};

use crate::ekf::{ATT, AidingSource, ErrorStateEkf, POS, UpdateOutcome};

mod config;
mod source_record;

pub use config::{IntegrityConfig, MAX_NIS_WINDOW};
use source_record::{MIN_REJECTED_RUN, SourceRecord};

/// Seconds of device time in whole microseconds, so that limits compare exactly.
fn micros(s: f64) -> u64 {
    (s * 1e6).round() as u64
}

/// The integrity monitor of one navigator.
#[derive(Debug, Clone)]
pub struct IntegrityMonitor {
    config: IntegrityConfig,
    /// `imu_outage_s`, `rejection_persist_s`, `recovery_s` in µs.
    outage_us: u64,
    persist_us: u64,
    recovery_us: u64,
    /// Sources the profile uses (index [`AidingSource`]).
    configured: [bool; AidingSource::COUNT],
    /// The reason bit of each source whose innovations are inconsistent (index
    /// [`AidingSource`]).
    inconsistency_reasons: [u32; AidingSource::COUNT],
    sources: [SourceRecord; AidingSource::COUNT],
    /// Newest device time seen on any IMU sample, µs.
    latest_us: u64,
    /// Device time of the first unusable IMU sample of the current outage.
    outage_since_us: Option<u64>,
    /// IMU samples in a row whose time did not advance.
    time_stalls: u32,
    /// Device time a recovery started (after an invalid episode or a reset).
    recovering_since_us: Option<u64>,
    /// The last evaluation.
    last: (Integrity, u32),
    /// Resets from each source so far.
    resets: [u64; AidingSource::COUNT],
    /// Fusion reports a fault it has detected and not isolated (last IMU sample).
    fault_unisolated: bool,
    /// Since a fault episode began: the attitude σ (rad) below which the hold after it ends.
    fault_release_sigma_rad: Option<f64>,
    /// No initial position was configured and no absolute fix has set one.
    position_unknown: bool,
    /// A fault episode left more attitude error than the limit: held degraded for good.
    fault_latched: bool,
}

impl IntegrityMonitor {
    /// A monitor for a profile that uses the sources marked in `configured`, each raising its
    /// reason of `inconsistency_reasons` when its innovations are inconsistent.
    pub fn new(
        config: IntegrityConfig,
        configured: [bool; AidingSource::COUNT],
        inconsistency_reasons: [u32; AidingSource::COUNT],
    ) -> Self {
        Self {
            config,
            outage_us: micros(config.imu_outage_s),
            persist_us: micros(config.rejection_persist_s),
            recovery_us: micros(config.recovery_s),
            configured,
            inconsistency_reasons,
            sources: [SourceRecord::default(); AidingSource::COUNT],
            latest_us: 0,
            outage_since_us: None,
            time_stalls: 0,
            recovering_since_us: None,
            last: (Integrity::Ok, 0),
            resets: [0; AidingSource::COUNT],
            fault_unisolated: false,
            fault_release_sigma_rad: None,
            position_unknown: false,
            fault_latched: false,
        }
    }

    /// Fusion's verdict on the IMU sample being integrated: whether it carries a fault detected
    /// and not isolated. `attitude_sigma_rad` is the largest attitude error σ now; at the start of
    /// an episode it sets the level the hold after the episode returns to.
    pub fn on_fusion_fault(&mut self, unisolated: bool, attitude_sigma_rad: f64) {
        if unisolated && self.fault_release_sigma_rad.is_none() {
            let limit = self.config.fault_attitude_sigma_deg.to_radians();
            self.fault_release_sigma_rad = Some(limit.max(attitude_sigma_rad));
        }
        self.fault_unisolated = unisolated;
    }

    /// A gyro fault episode ended (isolated, or the parity returned) having integrated up to
    /// `bound_rad` of attitude error. Beyond `fault_attitude_sigma_deg` nothing the navigator
    /// measures afterwards can be trusted to have found that error: the tilt is weakly observable
    /// without horizontal aiding, and a gravity re-levelling in flight takes any acceleration for
    /// tilt. The hold then lasts until the filter starts afresh (a new alignment or a take-over).
    pub fn on_fault_episode_end(&mut self, bound_rad: f64) {
        // A NaN bound is no bound: latched as well.
        if bound_rad.is_nan() || bound_rad > self.config.fault_attitude_sigma_deg.to_radians() {
            self.fault_latched = true;
        }
    }

    /// Whether the horizontal position is unknown (no configured origin, no absolute fix yet).
    pub fn set_position_unknown(&mut self, unknown: bool) {
        self.position_unknown = unknown;
    }

    /// The horizontal position is unknown.
    pub fn position_unknown(&self) -> bool {
        self.position_unknown
    }

    /// The settings the monitor was built with.
    pub fn config(&self) -> &IntegrityConfig {
        &self.config
    }

    fn see_time(&mut self, t_us: u64) {
        self.latest_us = self.latest_us.max(t_us);
    }

    /// An IMU sample propagated the state at `t_us`. Returns whether it ends a spell without
    /// propagation long enough to have made the solution invalid (the attitude is then lost).
    pub fn on_propagated(&mut self, t_us: u64) -> bool {
        self.see_time(t_us);
        let outage = self
            .outage_since_us
            .is_some_and(|since| t_us.saturating_sub(since) >= self.outage_us);
        let stalled = self.time_stalls >= self.config.time_stall_samples;
        self.outage_since_us = None;
        self.time_stalls = 0;
        outage || stalled
    }

    /// An IMU sample arrived whose device time did not advance (or jumped): not integrated.
    pub fn on_time_stall(&mut self, t_us: u64) {
        self.see_time(t_us);
        self.time_stalls = self.time_stalls.saturating_add(1);
    }

    /// No IMU sample at all from `last_us` until `t_us` (longer than the strapdown's largest
    /// step): an outage from `last_us` on, judged like one of unusable samples.
    pub fn on_gap(&mut self, last_us: u64, t_us: u64) {
        self.see_time(t_us);
        self.outage_since_us.get_or_insert(last_us);
    }

    /// A fused IMU sample arrived without a usable solution.
    pub fn on_unusable_imu(&mut self, t_us: u64) {
        self.see_time(t_us);
        self.outage_since_us.get_or_insert(t_us);
    }

    /// The outcome of one update of `source` at `t_us`; `dof` is the measurement's dimension.
    pub fn on_update(&mut self, source: AidingSource, t_us: u64, outcome: UpdateOutcome, dof: u32) {
        let window = self.config.nis_window as usize;
        let r = &mut self.sources[source as usize];
        r.attempts += 1;
        match outcome {
            UpdateOutcome::Accepted { d2 } => {
                r.rejected_since_us = None;
                r.rejected_run = 0;
                r.confirmed = true;
                r.nis[r.next] = d2 / f64::from(dof.max(1));
                r.next = (r.next + 1) % window;
                r.len = (r.len + 1).min(window);
            }
            UpdateOutcome::Rejected { .. } | UpdateOutcome::Singular => {
                r.rejected_since_us.get_or_insert(t_us);
                r.rejected_run = r.rejected_run.saturating_add(1);
            }
        }
    }

    /// Whether the filter should be reset from `source` now: its updates are persistently rejected
    /// and the policy allows it.
    pub fn wants_reset(&self, source: AidingSource, now_us: u64) -> bool {
        self.config.reset_from_aiding
            && self.sources[source as usize].persistently_rejected(now_us, self.persist_us)
    }

    /// The filter was reset from `source` at `t_us`: its record starts afresh and the solution is
    /// held as recovering.
    pub fn on_reset(&mut self, source: AidingSource, t_us: u64) {
        self.resets[source as usize] += 1;
        self.sources[source as usize] = SourceRecord::default();
        self.start_recovery(t_us);
    }

    /// Resets from each source so far.
    pub fn resets(&self) -> [u64; AidingSource::COUNT] {
        self.resets
    }

    fn start_recovery(&mut self, t_us: u64) {
        self.recovering_since_us = Some(t_us);
        for r in &mut self.sources {
            r.confirmed = false;
        }
    }

    /// The integrity now, with the reasons; `stale` tells which configured sources are silent.
    /// Call once per published solution.
    pub fn evaluate(
        &mut self,
        ekf: &ErrorStateEkf,
        stale: [bool; AidingSource::COUNT],
    ) -> (Integrity, u32) {
        let now = self.latest_us;
        let c = self.config;
        let (mut invalid, mut degraded) = (0u32, 0u32);
        if let Some(since) = self.outage_since_us {
            if now.saturating_sub(since) >= self.outage_us {
                invalid |= why::IMU_UNUSABLE;
            } else {
                degraded |= why::IMU_UNUSABLE;
            }
        }
        if self.time_stalls >= c.time_stall_samples {
            invalid |= why::TIME_NOT_ADVANCING;
        } else if self.time_stalls > 0 {
            degraded |= why::TIME_NOT_ADVANCING;
        }
        let state = ekf.state();
        let finite = state.attitude.coords.iter().all(|v| v.is_finite())
            && state.velocity_ned.iter().all(|v| v.is_finite())
            && [state.lat, state.lon, state.alt]
                .iter()
                .all(|v| v.is_finite());
        if !finite {
            invalid |= why::NON_FINITE;
        }

        let (mut reporting, mut rejected) = (0, 0);
        for source in AidingSource::ALL {
            let i = source as usize;
            let r = &self.sources[i];
            if !self.configured[i] {
                continue;
            }
            if stale[i] {
                degraded |= why::AIDING_STALE;
                continue;
            }
            if r.attempts == 0 {
                continue;
            }
            reporting += 1;
            let persistent = r.persistently_rejected(now, self.persist_us);
            if persistent {
                rejected += 1;
            }
            // Zero-velocity updates come every sample of a stance, their innovations strongly
            // correlated and their σ a tuning device: their NIS says nothing about consistency.
            let full = r.len >= c.nis_window as usize && source != AidingSource::Zupt;
            let high = full && r.mean_nis().is_some_and(|m| m > c.nis_limit);
            if r.rejected_run >= MIN_REJECTED_RUN || high {
                degraded |= self.inconsistency_reasons[i];
            }
        }
        if reporting > 0 && rejected == reporting {
            invalid |= why::ALL_AIDING_REJECTED;
        }
        if self.covariance_beyond_limits(ekf) {
            degraded |= why::COVARIANCE;
        }
        if self.fault_unisolated || self.fault_latched {
            degraded |= why::SENSOR_FAULT_UNISOLATED;
        } else if let Some(release) = self.fault_release_sigma_rad {
            // A NaN σ never releases.
            if attitude_sigma_rad(ekf) <= release {
                self.fault_release_sigma_rad = None;
            } else {
                degraded |= why::SENSOR_FAULT_UNISOLATED;
            }
        }
        if self.position_unknown {
            degraded |= why::POSITION_UNKNOWN;
        }

        // Leaving an invalid episode starts a recovery; a recovery ends once it has lasted and
        // every source that reports has agreed again.
        if invalid == 0 && self.last.0 == Integrity::Invalid {
            self.start_recovery(now);
        }
        if let Some(since) = self.recovering_since_us {
            let lasted = now.saturating_sub(since) >= self.recovery_us;
            let confirmed = AidingSource::ALL.iter().all(|s| {
                let i = *s as usize;
                let r = &self.sources[i];
                !self.configured[i] || stale[i] || r.attempts == 0 || r.confirmed
            });
            if lasted && confirmed && invalid == 0 {
                self.recovering_since_us = None;
            } else {
                degraded |= why::RECOVERING;
            }
        }
        self.last = if invalid != 0 {
            (Integrity::Invalid, invalid | degraded)
        } else if degraded != 0 {
            (Integrity::Degraded, degraded)
        } else {
            (Integrity::Ok, 0)
        };
        self.last
    }

    /// The last evaluation.
    pub fn last(&self) -> (Integrity, u32) {
        self.last
    }

    fn covariance_beyond_limits(&self, ekf: &ErrorStateEkf) -> bool {
        let c = &self.config;
        // A NaN σ is beyond any limit.
        let over = |sigma: f64, limit: f64| limit > 0.0 && (sigma.is_nan() || sigma > limit);
        let tilt = ekf.sigma(ATT).max(ekf.sigma(ATT + 1)).to_degrees();
        let heading = ekf.sigma(ATT + 2).to_degrees();
        let horizontal = ekf.sigma(POS).max(ekf.sigma(POS + 1));
        over(tilt, c.max_tilt_sigma_deg)
            || over(heading, c.max_heading_sigma_deg)
            || over(ekf.sigma(POS + 2), c.max_vertical_sigma_m)
            || over(horizontal, c.max_horizontal_sigma_m)
    }
}

/// The largest attitude error σ over the three axes, rad (NaN when any is).
pub fn attitude_sigma_rad(ekf: &ErrorStateEkf) -> f64 {
    let sigmas = [ATT, ATT + 1, ATT + 2].map(|i| ekf.sigma(i));
    if sigmas.iter().any(|s| s.is_nan()) {
        return f64::NAN;
    }
    sigmas.into_iter().fold(0.0, f64::max)
}
