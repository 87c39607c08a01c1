//! The aided navigator's inertial core: static alignment, then the error-state EKF predicted on
//! every IMU sample. It owns the filter, the stance detector, the records of the aiding sources
//! and the integrity monitor; the aiding sources ([`crate::aiding`]) own their settings and
//! state and reach the filter only through the `AidingContext` the core
//! lends them: the tilt and zero-velocity updates on each IMU sample, the readings of their own
//! topics (barometric heights, magnetometer samples, airspeeds) through
//! [`AidedNavigator::on_reading`], and GNSS fixes through [`AidedNavigator::on_gnss`].
//!
//! Both profiles run it — a foot-mounted unit (pedestrian) and the airframe (uav); the offline
//! evaluations and the live navigator share this one code path, so what the real recordings
//! measure is what flies.

use nalgebra::Vector3;

pub use crate::aided_config::AidedConfig;
use crate::aiding::context::{AidingContext, CorePhase, ImuNow};
use crate::aiding::gnss::measurement::{GnssMeasurement, GnssOutcome};
use crate::aiding::gnss::monitor::GnssMonitor;
use crate::aiding::outcome::AidingOutcome;
use crate::aiding::readings::Reading;
use crate::aiding::records::SourceRecords;
use crate::aiding::sources::AidingSources;
pub use crate::aiding::zupt::ZuptConfig;
use crate::alignment::{AlignError, Alignment, StaticAligner};
use crate::attitude_recovery::AttitudeRecovery;
use crate::ekf::{AidingSource, ErrorStateEkf};
use crate::force_delay::ForceDelay;
pub use crate::imu_step::ImuStep;
use crate::integrity::IntegrityMonitor;
use crate::mechanisation::{ImuBias, NominalState, StepOutcome};
use crate::stance::StanceDetector;
use crate::unisolated_fault::{FusionFault, UnisolatedFaultBound};
use ipc_types::Integrity;

/// Where the navigator is in its sequence. Held inline, not boxed, so that the step from
/// alignment to navigation does not allocate either (the live navigator may realign in flight).
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
enum Phase {
    Aligning(StaticAligner),
    Navigating(ErrorStateEkf),
}

/// Alignment followed by the EKF with zero-velocity updates. Allocation-free per sample once
/// aligned.
#[derive(Debug, Clone)]
pub struct AidedNavigator {
    config: AidedConfig,
    phase: Phase,
    stance: StanceDetector,
    alignment: Option<Alignment>,
    last_align_error: Option<AlignError>,
    last_time_us: Option<u64>,
    /// Bias-corrected specific force of the last propagated sample, m/s².
    last_force: Vector3<f64>,
    /// The stance detector fired on the last sample.
    in_stance: bool,
    /// The last reading and the last accepted update of every aiding source.
    records: SourceRecords,
    /// Whether the solution can be used (see [`crate::integrity`]).
    integrity: IntegrityMonitor,
    /// Re-levelling after the attitude was lost (see [`crate::attitude_recovery`]).
    attitude_recovery: AttitudeRecovery,
    /// The aiding sources, each with its settings and state (see [`crate::aiding`]).
    sources: AidingSources,
    /// A fault fusion detected and has not isolated (see [`crate::unisolated_fault`]).
    fusion_fault: UnisolatedFaultBound,
    /// The specific force delayed to the rate's instant (see [`crate::force_delay`]).
    force_delay: ForceDelay,
}

impl AidedNavigator {
    /// A navigator that starts aligning with the first IMU sample.
    pub fn new(config: AidedConfig) -> Self {
        let stance = StanceDetector::new(config.stance);
        Self {
            config,
            phase: Phase::Aligning(StaticAligner::new(config.align)),
            stance,
            alignment: None,
            last_align_error: None,
            last_time_us: None,
            last_force: Vector3::zeros(),
            in_stance: false,
            records: SourceRecords::new(config.watched_sources(), config.stale_after_s),
            integrity: Self::integrity_monitor(&config),
            attitude_recovery: AttitudeRecovery::default(),
            sources: config.sources(),
            fusion_fault: UnisolatedFaultBound::default(),
            force_delay: ForceDelay::new(config.gyro_lag_s),
        }
    }

    fn integrity_monitor(config: &AidedConfig) -> IntegrityMonitor {
        let mut monitor = IntegrityMonitor::new(
            config.integrity,
            config.configured_sources(),
            config.inconsistency_reasons(),
        );
        monitor.set_position_unknown(!config.origin_known);
        monitor
    }

    /// Fusion's fault report for the IMU sample about to be fed (see
    /// [`crate::unisolated_fault`]).
    pub fn on_fusion_fault(&mut self, fault: FusionFault) {
        let ended = self.fusion_fault.current().gyro_unisolated && !fault.gyro_unisolated;
        if ended {
            self.integrity
                .on_fault_episode_end(self.fusion_fault.bound_rad());
        }
        self.fusion_fault.set(fault);
    }

    /// The horizontal position is known now (an absolute fix set it, or the solution taken over
    /// had one), or not.
    pub fn set_position_known(&mut self, known: bool) {
        self.integrity.set_position_unknown(!known);
    }

    /// Navigates from now on from another filter's solution at device time `t_us`: its nominal
    /// state, bias estimates and error variances (`covariance_diag`, correlations unknown). The
    /// altitude is already baro-aided, so no baro reading re-sets it; the magnetometer reference
    /// is taken from the next magnetometer sample at the taken-over attitude.
    pub fn take_over(
        &mut self,
        t_us: u64,
        state: NominalState,
        bias: ImuBias,
        covariance_diag: &[f64; crate::ekf::STATES],
    ) {
        let mut ekf = ErrorStateEkf::new(state, bias, self.config.strapdown, self.config.noise);
        ekf.set_covariance_diagonal(covariance_diag);
        self.stance = StanceDetector::new(self.config.stance);
        self.force_delay = ForceDelay::new(self.config.gyro_lag_s);
        self.alignment = None;
        self.last_align_error = None;
        self.last_time_us = Some(t_us);
        self.sources.on_take_over(state.alt);
        self.records.start_navigating(Some(t_us));
        self.integrity = Self::integrity_monitor(&self.config);
        self.fusion_fault = UnisolatedFaultBound::default();
        self.attitude_recovery = AttitudeRecovery::default();
        self.phase = Phase::Navigating(ekf);
    }

    /// True when `source` is in use but has gone quiet: no valid reading for `stale_after_s`
    /// (counted from the start of navigation when it never reported). Always false while
    /// aligning and for a disabled source.
    pub fn is_stale(&self, source: AidingSource) -> bool {
        self.records.is_stale(source, self.last_time_us)
    }

    /// The settings in use.
    pub fn config(&self) -> &AidedConfig {
        &self.config
    }

    /// True once aligned.
    pub fn is_navigating(&self) -> bool {
        matches!(self.phase, Phase::Navigating(_))
    }

    /// The core as lent to an aiding source for one reading, and the sources.
    fn lend(&mut self) -> (AidingContext<'_>, &mut AidingSources) {
        let phase = match &mut self.phase {
            Phase::Navigating(ekf) => CorePhase::Navigating(ekf),
            Phase::Aligning(aligner) => CorePhase::Aligning(aligner),
        };
        let imu = ImuNow {
            time_us: self.last_time_us,
            in_stance: self.in_stance,
            force: self.last_force,
        };
        let ctx = AidingContext::new(phase, imu, &mut self.records, &mut self.integrity);
        (ctx, &mut self.sources)
    }

    /// One held aiding reading (a barometric height, a magnetometer sample, an airspeed: see
    /// [`crate::aiding::readings`]), applied by its source.
    pub fn on_reading(&mut self, r: Reading) -> AidingOutcome {
        let (mut ctx, sources) = self.lend();
        r.apply(&mut ctx, sources)
    }

    /// One receiver fix (see [`crate::aiding::gnss`]).
    pub fn on_gnss(&mut self, m: &GnssMeasurement) -> GnssOutcome {
        let (mut ctx, sources) = self.lend();
        sources.gnss.on_fix(&mut ctx, m)
    }

    /// The GNSS receiver's consistency monitor.
    pub fn gnss_monitor(&self) -> &GnssMonitor {
        self.sources.gnss.monitor()
    }

    /// Device time of the last IMU sample, µs.
    pub fn time_us(&self) -> Option<u64> {
        self.last_time_us
    }

    /// Device time of the last accepted update from `source`, µs.
    pub fn last_accepted_us(&self, source: AidingSource) -> Option<u64> {
        self.records.last_accepted_us(source)
    }

    /// The filter, once aligned.
    pub fn ekf(&self) -> Option<&ErrorStateEkf> {
        match &self.phase {
            Phase::Navigating(ekf) => Some(ekf),
            Phase::Aligning(_) => None,
        }
    }

    /// The last successful alignment; `None` while aligning and after a take-over from the peer
    /// lane (which did not align).
    pub fn alignment(&self) -> Option<&Alignment> {
        self.alignment.as_ref()
    }

    /// Why the last alignment window was discarded.
    pub fn last_align_error(&self) -> Option<&AlignError> {
        self.last_align_error.as_ref()
    }

    /// Feeds one IMU sample at device time `t_us`: rate rad/s, specific force m/s², body FRD, and
    /// the foot pressure when the unit has a sensor.
    pub fn on_imu(
        &mut self,
        t_us: u64,
        rate_rps: [f64; 3],
        specific_force: [f64; 3],
        pressure: Option<f64>,
    ) -> ImuStep {
        let specific_force = self.force_delay.push(t_us, specific_force);
        let previous_time_us = self.last_time_us;
        let dt_s = previous_time_us.map_or(0.0, |last| t_us.saturating_sub(last) as f64 * 1e-6);
        self.last_time_us = Some(t_us);
        let mut step = ImuStep {
            propagated: None,
            stance: false,
            zupt: None,
        };
        match &mut self.phase {
            Phase::Aligning(aligner) => {
                aligner.push_imu(t_us, rate_rps, specific_force);
                if aligner.is_complete() {
                    match aligner.finish(self.config.declination_rad) {
                        Ok(a) => self.start(a),
                        Err(e) => {
                            self.last_align_error = Some(e);
                            aligner.reset();
                        }
                    }
                }
            }
            Phase::Navigating(ekf) => {
                let outcome = ekf.predict(rate_rps, specific_force, dt_s);
                step.propagated = Some(outcome);
                match outcome {
                    StepOutcome::Applied => {
                        if self.integrity.on_propagated(t_us) {
                            self.attitude_recovery.lose(ekf, &self.config.integrity);
                        }
                        let widen = self.fusion_fault.on_step(dt_s);
                        for k in 0..3 {
                            ekf.inflate_component(crate::ekf::ATT + k, widen);
                        }
                        self.integrity.on_fusion_fault(
                            self.fusion_fault.current().unisolated(),
                            crate::integrity::attitude_sigma_rad(ekf),
                        );
                    }
                    // Forward beyond `max_dt_s`: nothing arrived for that long, an outage like
                    // any other; not forward: the device time did not advance.
                    StepOutcome::InvalidDt => match previous_time_us {
                        Some(last) if t_us > last => self.integrity.on_gap(last, t_us),
                        _ => self.integrity.on_time_stall(t_us),
                    },
                    StepOutcome::NonFiniteInput => {
                        // The epoch stays: the next good sample integrates across this one.
                        self.last_time_us = previous_time_us;
                        self.integrity.on_unusable_imu(t_us);
                        return step;
                    }
                }
                // The detector sees bias-corrected rates, so a gyro bias the filter has learnt
                // does not read as motion.
                let b = ekf.bias();
                let rate = Vector3::from(rate_rps) - b.gyro_rps;
                let force = Vector3::from(specific_force) - b.accel_mps2;
                self.last_force = force;
                if outcome.is_applied()
                    && let Some(result) = self.attitude_recovery.push(
                        ekf,
                        &self.config.integrity,
                        t_us,
                        specific_force,
                        &rate,
                    )
                {
                    self.records.book_update(
                        &mut self.integrity,
                        AidingSource::Gravity,
                        t_us,
                        result,
                        2,
                    );
                }
                // The stream as the sources that run on this sample see it: the stance is the
                // previous sample's until the detector below has seen this one.
                let imu = ImuNow {
                    time_us: self.last_time_us,
                    in_stance: self.in_stance,
                    force,
                };
                if outcome.is_applied() && !self.attitude_recovery.is_lost() {
                    let mut ctx = lend_on_imu(ekf, &mut self.records, &mut self.integrity, imu);
                    self.sources
                        .tilt
                        .on_imu(&mut ctx, t_us, specific_force, &rate);
                }
                let g = ekf.strapdown().gravity();
                step.stance = self
                    .stance
                    .push(rate.into(), force.into(), pressure, g, dt_s);
                self.in_stance = step.stance;
                if step.stance && outcome.is_applied() {
                    let imu = ImuNow {
                        in_stance: self.in_stance,
                        ..imu
                    };
                    let mut ctx = lend_on_imu(ekf, &mut self.records, &mut self.integrity, imu);
                    step.zupt = self.sources.zupt.on_stance(&mut ctx, t_us);
                }
                if outcome.is_applied() {
                    self.sources.gnss.on_imu(ekf, t_us, rate);
                }
            }
        }
        step
    }

    /// A fused IMU sample at `t_us` without a usable solution (too few channels, a saturated
    /// block, a rejected frame): nothing to integrate. The state stands still, the integrity
    /// monitor counts the outage, and the next usable sample integrates from this time on (the
    /// outage is skipped, not integrated across with the first rates after it).
    pub fn on_unusable_imu(&mut self, t_us: u64) {
        if self.is_navigating() {
            self.integrity.on_unusable_imu(t_us);
            if self.last_time_us.is_none_or(|last| t_us > last) {
                self.last_time_us = Some(t_us);
            }
        }
    }

    /// The integrity of the solution now, with its reasons (bits of
    /// [`ipc_types::integrity_reason`]); `Invalid` with no reason while aligning. Evaluate once
    /// per solution published: leaving an invalid episode starts a recovery.
    pub fn evaluate_integrity(&mut self) -> (Integrity, u32) {
        let stale = AidingSource::ALL.map(|s| self.is_stale(s));
        match &self.phase {
            Phase::Navigating(ekf) => {
                let (integrity, reasons) = self.integrity.evaluate(ekf, stale);
                // A receiver judged inconsistent leaves the solution usable (it coasts on the
                // inertial one) but no longer vouched for by every source.
                if self.sources.gnss.monitor().rejected().is_some() {
                    let degraded = match integrity {
                        Integrity::Ok => Integrity::Degraded,
                        other => other,
                    };
                    (
                        degraded,
                        reasons | ipc_types::integrity_reason::GNSS_INCONSISTENT,
                    )
                } else {
                    (integrity, reasons)
                }
            }
            Phase::Aligning(_) => (Integrity::Invalid, 0),
        }
    }

    /// Resets of the filter from each aiding source so far (see [`crate::integrity`]).
    pub fn resets(&self) -> [u64; AidingSource::COUNT] {
        self.integrity.resets()
    }

    /// Starts the filter from a good alignment window: attitude and gyro bias from the window,
    /// position from the configuration, altitude from the first valid baro reading when there was
    /// one. The component of the mean specific force along itself in excess of model gravity is
    /// taken as accelerometer bias, so the window integrates to zero velocity: at rest only this
    /// component is observable, the rest of the bias is absorbed in roll and pitch.
    fn start(&mut self, a: Alignment) {
        let [lat, lon, alt] = self.config.origin;
        let initial_height_m = self.sources.baro.initial_height_m();
        let mut state = NominalState::at_rest(lat, lon, initial_height_m.unwrap_or(alt));
        state.attitude = a.attitude;
        let mut ekf = ErrorStateEkf::new(
            state,
            ImuBias::default(),
            self.config.strapdown,
            self.config.noise,
        );
        let f = a.mean_specific_force_mps2;
        let magnitude = f.norm();
        let accel_bias = if magnitude > 0.0 {
            f * (1.0 - ekf.strapdown().gravity() / magnitude)
        } else {
            Vector3::zeros()
        };
        ekf.set_bias(ImuBias {
            gyro_rps: a.gyro_bias_rps,
            accel_mps2: accel_bias,
        });
        self.sources.on_aligned(&a);
        self.alignment = Some(a);
        self.records.start_navigating(self.last_time_us);
        self.phase = Phase::Navigating(ekf);
    }
}

/// The core as lent, while navigating, to an aiding source that runs on the IMU sample just
/// propagated (tilt, zero velocity): the filter `ekf`, the records and integrity monitor its
/// updates are booked in, and the stream as of that sample, `imu`.
fn lend_on_imu<'a>(
    ekf: &'a mut ErrorStateEkf,
    records: &'a mut SourceRecords,
    integrity: &'a mut IntegrityMonitor,
    imu: ImuNow,
) -> AidingContext<'a> {
    AidingContext::new(CorePhase::Navigating(ekf), imu, records, integrity)
}
