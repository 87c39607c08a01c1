//! The GNSS receiver as an aiding source: position and velocity fixes, each compared with the
//! filter's state at the instant the receiver measured (see [`crate::state_history`]), judged by
//! the consistency monitor ([`monitor`]) and the displacement test ([`displacement`]), and
//! applied when the receiver is believed. A fix after an outage, or the first one without a
//! known position, re-sets the position instead.

pub mod config;
pub mod displacement;
pub mod hold;
pub mod measurement;
pub mod monitor;

use nalgebra::Vector3;

use self::config::GnssAidingConfig;
use self::displacement::DisplacementTest;
use self::measurement::{GnssMeasurement, GnssOutcome};
use self::monitor::{GnssMonitor, Verdict};
use crate::aiding::context::AidingContext;
use crate::ekf::gnss::{antenna_position, antenna_velocity};
use crate::ekf::{AidingSource, ErrorStateEkf, POS, UpdateOutcome, VEL};
use crate::state_history::{HistoryError, PastState, StateHistory};

/// The GNSS aiding: its settings and what it keeps between fixes.
#[derive(Debug, Clone)]
pub(crate) struct GnssAiding {
    config: GnssAidingConfig,
    /// Recent states, for fixes measured before the IMU stream's present.
    history: StateHistory,
    /// Whether the receiver is believed.
    monitor: GnssMonitor,
    /// The receiver time of the last fix taken, µs.
    last_receiver_time_us: Option<u64>,
    /// The horizontal distance of the fixes from the solution when the receiver was rejected, m.
    jump_offset_m: Option<f64>,
    /// The receiver's displacement against the inertial velocity (the gain-free drift test).
    displacement: DisplacementTest,
}

impl GnssAiding {
    pub(crate) fn new(config: GnssAidingConfig) -> Self {
        Self {
            config,
            history: StateHistory::default(),
            monitor: GnssMonitor::new(config),
            last_receiver_time_us: None,
            jump_offset_m: None,
            displacement: DisplacementTest::default(),
        }
    }

    /// Forgets everything for a new solution, keeping the history's storage (no allocation on
    /// the sample that starts navigation).
    pub(crate) fn reset(&mut self) {
        self.history.clear();
        self.monitor = GnssMonitor::new(self.config);
        self.last_receiver_time_us = None;
        self.jump_offset_m = None;
        self.displacement.reset();
    }

    /// The receiver's consistency monitor.
    pub(crate) fn monitor(&self) -> &GnssMonitor {
        &self.monitor
    }

    /// One propagated IMU sample at `t_us` (rate bias-corrected): remembered for the fixes that
    /// will have been measured at its time.
    pub(crate) fn on_imu(&mut self, ekf: &ErrorStateEkf, t_us: u64, rate: Vector3<f64>) {
        if self.config.enabled {
            self.history.record(t_us, ekf, rate);
        }
    }

    /// One receiver fix (see [`GnssMeasurement`]).
    pub(crate) fn on_fix(
        &mut self,
        ctx: &mut AidingContext<'_>,
        m: &GnssMeasurement,
    ) -> GnssOutcome {
        let c = self.config;
        if !c.enabled || ctx.filter().is_none() {
            return GnssOutcome::NotUsed;
        }
        if !m.fix_3d || !m.is_finite() {
            return GnssOutcome::NoFix;
        }
        if self
            .last_receiver_time_us
            .is_some_and(|last| m.receiver_time_us <= last)
        {
            return GnssOutcome::Repeated;
        }
        self.last_receiver_time_us = Some(m.receiver_time_us);
        // Back after an outage: the position has coasted, its covariance grown and its
        // correlations with velocity and attitude stretched far beyond what one fix can sort out;
        // the fix re-sets the position (and velocity) instead of being gated against it.
        // Without a known position, the first fix sets it the same way: gated against a
        // placeholder, it would only ever be rejected.
        let returning = ctx.is_stale(AidingSource::Gnss) || ctx.position_unknown();
        ctx.note_reading(AidingSource::Gnss, m.t_us);
        if returning && self.monitor.rejected().is_none() {
            return self.reset_from_fix(ctx, m);
        }
        let Some(ekf) = ctx.filter() else {
            return GnssOutcome::NotUsed;
        };
        let past = match self.history.at(m.t_us, ekf.corrections()) {
            Ok(past) => past,
            Err(HistoryError::TooOld | HistoryError::Empty) => return GnssOutcome::TooOld,
        };
        let arm = Vector3::from(c.lever_arm_m);
        let position = antenna_position(
            &past,
            m.position,
            &arm,
            floor(m.sigma_h_m, c.sigma_horizontal_floor_m),
            floor(m.sigma_v_m, c.sigma_vertical_floor_m),
        );
        let Some((s, d2)) = ekf.test(&position) else {
            return GnssOutcome::Outlier;
        };
        let normalised = [0, 1].map(|k| position.innovation[k] / s[(k, k)].max(0.0).sqrt());
        // A rejected receiver stays out while its fixes are still at least half as far from the
        // solution as when it was rejected: the coast's growing covariance would in time make a
        // persistent jump look consistent, and a drift that goes on never leaves the gate at
        // all. A receiver that jumped back is judged by the covariance as it has grown, which
        // includes the coast's own drift.
        let offset_m = position.innovation.x.hypot(position.innovation.y);
        let d2 = match (self.monitor.rejected(), self.jump_offset_m) {
            (Some(_), Some(at_rejection)) if offset_m >= 0.5 * at_rejection => f64::INFINITY,
            _ => d2,
        };
        let mut verdict = self.monitor.judge(m.t_us, d2, normalised);
        if verdict == Verdict::Use {
            let sigma_h = floor(m.sigma_h_m, c.sigma_horizontal_floor_m);
            // The receiver's own velocity where it reports one (see `displacement` for why not
            // the solution's), the solution's otherwise.
            let velocity = m.velocity_ned.map_or(past.velocity_ned, Vector3::from);
            let displaced = self
                .displacement
                .push(m.t_us, m.position, &velocity, sigma_h);
            if displaced.is_some_and(|d| d > c.displacement_threshold) {
                self.monitor.reject_for_drift(m.t_us);
                verdict = Verdict::Rejected;
            }
        } else {
            self.displacement.reset();
        }
        if verdict == Verdict::Rejected && self.jump_offset_m.is_none() {
            self.jump_offset_m = Some(offset_m);
        }
        if verdict == Verdict::Readmitted {
            self.jump_offset_m = None;
        }
        match verdict {
            Verdict::Use => {}
            // Back after coasting: the fix re-sets the position as after an outage, for the
            // same reason (see `reset_from_fix`).
            Verdict::Readmitted => return self.reset_from_fix(ctx, m),
            Verdict::Outlier => return GnssOutcome::Outlier,
            Verdict::Rejected => return GnssOutcome::Rejected,
        }
        let velocity = m.velocity_ned.filter(|_| c.use_velocity).map(|v| {
            antenna_velocity(
                &past,
                v,
                &arm,
                floor(m.sigma_vel_mps, c.sigma_velocity_floor_mps),
            )
        });
        let Some(ekf) = ctx.filter_mut() else {
            return GnssOutcome::NotUsed;
        };
        let outcome = ekf.apply(AidingSource::Gnss, &position, c.gate);
        if let Some(v) = velocity {
            let _ = ekf.apply(AidingSource::Gnss, &v, c.gate);
        }
        if outcome.is_accepted() {
            ctx.note_accepted(AidingSource::Gnss, m.t_us);
        }
        match outcome {
            UpdateOutcome::Accepted { d2 } => GnssOutcome::Applied { d2 },
            _ => GnssOutcome::Outlier,
        }
    }

    /// Re-sets the position (and the velocity, when reported) from the fix `m` after an outage
    /// or a re-admission: the antenna's position less the lever arm, its correlations dropped,
    /// its variance the fix's. The fix's measurement instant is taken as now (the outage was much
    /// longer than the receiver's latency; the latency's motion is within the variance given
    /// here).
    fn reset_from_fix(&mut self, ctx: &mut AidingContext<'_>, m: &GnssMeasurement) -> GnssOutcome {
        let c = self.config;
        self.displacement.reset();
        let Some(ekf) = ctx.filter_mut() else {
            return GnssOutcome::NotUsed;
        };
        let past = PastState::now(ekf, Vector3::zeros());
        let arm = Vector3::from(c.lever_arm_m);
        let fix = antenna_position(&past, m.position, &arm, 1.0, 1.0);
        let (sh, sv) = (
            floor(m.sigma_h_m, c.sigma_horizontal_floor_m),
            floor(m.sigma_v_m, c.sigma_vertical_floor_m),
        );
        // Move by the innovation (fix − predicted antenna), then forget the old uncertainty.
        let d = fix.innovation;
        let s = ekf.state_mut();
        [s.lat, s.lon, s.alt] =
            rins_earth::LocalOrigin::new(s.lat, s.lon, s.alt).geodetic(d.into());
        for (k, sigma) in [sh, sh, sv].into_iter().enumerate() {
            ekf.reset_component(POS + k, sigma * sigma);
        }
        if let Some(v) = m.velocity_ned.filter(|_| c.use_velocity) {
            let sigma = floor(m.sigma_vel_mps, c.sigma_velocity_floor_mps);
            ekf.state_mut().velocity_ned = Vector3::from(v);
            for k in 0..3 {
                ekf.reset_component(VEL + k, sigma * sigma);
            }
        }
        self.history.clear();
        ctx.note_accepted(AidingSource::Gnss, m.t_us);
        ctx.set_position_known();
        GnssOutcome::Readmitted
    }
}

/// The reported σ, raised to `min` (a σ that is not a number is `min`).
fn floor(sigma: f64, min: f64) -> f64 {
    if sigma.is_finite() {
        sigma.max(min)
    } else {
        min
    }
}
