//! Fault detection, isolation and reconfiguration of one sensor type: channel health, parity test
//! with persistence, GLT / stationary-reference isolation, latched exclusions and the rebuild of
//! the solver and parity space when the active set changes.
//!
//! Per sample, in this order (so a channel found bad on this sample is already out of this
//! sample's solution):
//! 1. invalid channels are excluded (Missing); health checks: stuck and noisy channels are
//!    excluded; a channel saturated for `saturation_samples` is excluded when the other channels
//!    say it should be well inside its range, otherwise (genuine over-range) it is Suspect;
//! 2. any exclusion → reconfiguration;
//! 3. parity test on the offset-corrected parity vector ([`super::offset`]; declarations are
//!    suspended during the learning phase at start), per sample with k-of-n persistence and on
//!    its windowed mean ([`super::mean_shift`]) for biases too small for single samples; on a
//!    declaration: the GLT over the alarm episode (or over the windowed mean) isolates and
//!    excludes the channel when it clearly wins (N_active ≥ 5, no twins; see
//!    [`super::isolation`]); otherwise, while stationary, the reference may isolate
//!    it among the contenders ([`super::stationary`]); otherwise the candidates are Suspect, the
//!    fault is reported as detected-not-isolated, and every channel stays in the solution;
//! 4. weighted least squares over the active set, on the values less the correction of
//!    [`solve_correction`] (the parity part of the residual channel biases, taken up at each
//!    reconfiguration so that the solution does not step).
//!
//! **Exclusions latch.** While the type has a solution, an excluded channel is never re-admitted
//! automatically, not even when it looks healthy again. In 2005 the air data inertial reference
//! unit of a Boeing 777 (Malaysia Airlines 124), after a second accelerometer failed, went back to
//! an accelerometer that had failed years before — that earlier exclusion had not been kept — and
//! its wrong output pitched the aircraft up. Only an explicit command ([`SensorMonitor::readmit`])
//! returns a channel then. Once fewer than three channels remain, there is no solution left to
//! protect: with `readmit = "auto"` (the default) the excluded channels are re-tested and return
//! when they are consistent again ([`super::recovery`]); `readmit = "operator"` keeps the latch.
//!
//! **Block saturation.** When fewer than three channels in service are off the converter rails,
//! the true value lies beyond the range and no combination of the channels measures it: the
//! status says `block_saturated` and the fused solution is flagged not valid. Nothing is
//! excluded (an over-range is not a channel fault) and the channels are Suspect (Saturated).

mod fault_bound;
mod health;
mod parity_decision;
mod probation;
mod solve_correction;
mod status;

use super::MAX_PARITY;
use super::channel_health::ChannelHealth;
use super::config::{FdiSettings, ParityNoise};
use super::isolation::ParityWindow;
use super::mean_shift::MeanShift;
use super::noise_estimate::AdaptiveParityNoise;
use super::offset::ParityOffset;
use super::parity::ParitySpace;
use super::persistence::Persistence;
use super::probation::ProbationTest;
use super::recovery::ExclusionRetest;
use super::report::{ChannelEvents, SensorStatus};
use super::stationary::ChannelReference;
use crate::geometry::{Geometry, MAX_CHANNELS};
use crate::wls::WlsSolver;
use ipc_types::{ChannelState, FaultReason, SensorType};
use parity_decision::motion_variance;
use solve_correction::SolveCorrection;
use status::{HealthOutcome, ParityOutcome};

/// One sample of one sensor type as the monitor sees it.
#[derive(Debug, Clone, Copy)]
pub struct MonitorInput<'a> {
    /// Raw converter counts (channel i at index i; a short slice means missing channels).
    pub counts: &'a [i16],
    /// Calibrated values, SI units (NaN for channels without a sample).
    pub z: &'a [f64; MAX_CHANNELS],
    /// Channels with a valid sample (valid bit set and present in `counts`).
    pub valid: u32,
    /// The device reports an error.
    pub device_error: bool,
    /// Channels whose module temperature is outside the calibrated range.
    pub temperature_suspect: u32,
}

/// The fused 3-axis estimate of one sensor type.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SensorEstimate {
    /// Estimate (zeros when `!ok`).
    pub x: [f64; 3],
    /// Variance of each axis (zeros when `!ok`).
    pub var: [f64; 3],
    /// At least three active, well-conditioned channels.
    pub ok: bool,
    /// Channels in the solution.
    pub mask: u32,
}

/// Why a readmit command was refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{sensor} channel {channel} does not exist ({n} channels fitted)")]
pub struct ReadmitError {
    /// The sensor type's name (`gyro`, `accel`).
    pub sensor: &'static str,
    /// The channel asked for.
    pub channel: usize,
    /// Channels the sensor type has.
    pub n: usize,
}

/// The indices of the bits set in `mask`, lowest first.
fn bits(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// Fault detection, isolation and reconfiguration state of one sensor type.
#[derive(Debug, Clone)]
pub struct SensorMonitor {
    sensor: SensorType,
    geometry: Geometry,
    variances: [f64; MAX_CHANNELS],
    settings: FdiSettings,
    /// SI value of each channel at the lower and upper converter rail.
    rail_values: [[f64; 2]; MAX_CHANNELS],
    /// Latched exclusion reason per channel (`None` = in service).
    excluded: [FaultReason; MAX_CHANNELS],
    excluded_mask: u32,
    solver: Option<WlsSolver>,
    parity: Option<ParitySpace>,
    threshold: f64,
    persistence: Persistence,
    window: ParityWindow,
    /// Samples since the first exceedance of the current alarm episode (0: no episode).
    episode: usize,
    /// The windowed mean of the parity, for biases below the per-sample test.
    mean_shift: MeanShift,
    /// Samples since the active set last changed (the offset's re-learning).
    relearned: u64,
    health: ChannelHealth,
    /// Noise outliers that could not be excluded (3 active), held until the next verdict.
    noisy_suspect: u32,
    adaptive: Option<AdaptiveParityNoise>,
    offset: Option<ParityOffset>,
    /// Samples seen so far (for the learning phase).
    seen: u64,
    reference: ChannelReference,
    status: SensorStatus,
    /// The previous solution, for the rate of change in [`Self::motion_variance`].
    last_x: [f64; 3],
    /// Channel variance the motion adds now (see [`FdiSettings::motion_noise_fraction`]).
    motion_variance: f64,
    /// The solution before the test of this sample, where the offset is taken (with motion).
    test_x: [f64; 3],
    /// Subtracted from the values before the solve (see [`solve_correction`]).
    correction: SolveCorrection,
    /// Re-test of the exclusions while the type has no solution.
    retest: ExclusionRetest,
    /// Channels re-admitted by command, tested out of the solution (see [`super::probation`]).
    probation: ProbationTest,
}

impl SensorMonitor {
    /// The monitor of `sensor` with all channels of `geometry` in service. `variances`: channel
    /// noise σ² (first N entries); `rail_values`: each channel's calibrated value at the lower and
    /// upper converter rail. Builds the full-set solver and parity space (allocates).
    pub fn new(
        sensor: SensorType,
        geometry: Geometry,
        variances: [f64; MAX_CHANNELS],
        rail_values: [[f64; 2]; MAX_CHANNELS],
        settings: FdiSettings,
    ) -> Self {
        let n = geometry.n();
        let mut status = SensorStatus::ABSENT;
        status.n = n;
        status.states[..n].fill(ChannelState::Ok);
        let adaptive = (settings.parity_noise == ParityNoise::Adaptive)
            .then(|| AdaptiveParityNoise::new(settings.adaptive_window));
        let offset = (settings.parity_offset_window > 0).then(|| match settings.motion_offset {
            true => ParityOffset::with_motion(settings.parity_offset_window),
            false => ParityOffset::new(settings.parity_offset_window),
        });
        let health = ChannelHealth::new(geometry.axes(), &variances, settings.health);
        let mut monitor = Self {
            sensor,
            geometry,
            variances,
            settings,
            rail_values,
            excluded: [FaultReason::None; MAX_CHANNELS],
            excluded_mask: 0,
            solver: None,
            parity: None,
            threshold: f64::INFINITY,
            persistence: Persistence::new(settings.persistence_k, settings.persistence_n),
            window: ParityWindow::default(),
            episode: 0,
            mean_shift: MeanShift::new(settings.mean_shift_window),
            relearned: 0,
            health,
            noisy_suspect: 0,
            adaptive,
            offset,
            seen: 0,
            reference: ChannelReference::new(
                settings.stationary.window,
                settings.persistence_n as usize,
                settings.mean_shift_window,
                sensor == SensorType::Gyro,
            ),
            status,
            last_x: [0.0; 3],
            motion_variance: 0.0,
            test_x: [0.0; 3],
            correction: SolveCorrection::new(settings.parity_offset_window),
            retest: ExclusionRetest::default(),
            probation: ProbationTest::new(
                settings.readmit_probation_samples,
                settings.thresholds[1],
            ),
        };
        monitor.reconfigure();
        monitor
    }

    /// Processes one sample: detection, isolation, reconfiguration, then the solution over the
    /// active channels. `stationary`: the vehicle is stationary now. State changes are appended to
    /// `events`. Allocates only when the active set changes.
    pub fn step(
        &mut self,
        input: &MonitorInput,
        stationary: bool,
        events: &mut ChannelEvents,
    ) -> (SensorEstimate, SensorStatus) {
        let z = input.z;
        let before = self.excluded_mask;

        for ch in bits(self.active_mask() & !input.valid) {
            self.exclude(ch, FaultReason::Missing);
        }
        let found = self
            .health
            .check(input.counts, z, self.judged_mask(input.valid));
        let saturated_suspect = self.apply_health(&found, z);
        if self.excluded_mask != before {
            self.reconfigure();
        }
        self.probation_step(&found, input);
        let active = self.active_mask();
        let health = HealthOutcome {
            saturated_suspect,
            block_saturated: active.count_ones() >= 3 && (active & !found.at_rail).count_ones() < 3,
            auto_readmitted: self.retest_exclusions(input),
            noise_peak: found.noise_peak,
        };

        // The solution before the test sets the motion's share of the noise for this sample.
        let corrected = self.correction.apply(z);
        let before_test = self
            .solver
            .as_ref()
            .map(|s| (s.mask(), s.solve(&corrected)));
        if let Some((_, (x, _))) = &before_test {
            self.motion_variance = motion_variance(&self.settings, x, &self.last_x);
            self.test_x = *x;
        }
        let (t, candidates, learning) = self.parity_test(z, stationary);

        let estimate = match &self.solver {
            Some(solver) => {
                let values = self.correction.apply(z);
                let (x, mut var) = match before_test {
                    Some((mask, solution)) if mask == solver.mask() => solution,
                    // The test reconfigured: the correction has moved with the set.
                    _ => solver.solve(&values),
                };
                // A fault declared and not isolated is still in the solution: its variance
                // carries how far that fault can have moved it (see `fault_bound`).
                if candidates != 0 {
                    let bound = fault_bound::solution_error_bound(
                        solver,
                        self.geometry.axes(),
                        &values,
                        &x,
                        candidates,
                    );
                    var.iter_mut().for_each(|v| *v += bound * bound);
                }
                self.last_x = x;
                SensorEstimate {
                    x,
                    var,
                    ok: true,
                    mask: solver.mask(),
                }
            }
            None => SensorEstimate {
                mask: self.active_mask(),
                ..SensorEstimate::default()
            },
        };

        let dim = self.parity_dimension();
        let parity = ParityOutcome {
            t,
            dim,
            candidates,
            learning,
        };
        let status = self.build_status(&parity, &health, input);
        events.record(self.sensor, &self.status, &status);
        self.status = status;
        (estimate, status)
    }

    /// Closes a stationary-detector block (see [`super::stationary`]).
    pub fn end_block(&mut self, stationary: bool) {
        let dim = self.parity_dimension();
        self.reference.end_block(stationary, dim);
    }

    /// Tells the monitor that the input values will be shifted by `−bias` (per channel, SI) from
    /// the next sample on — a bias estimated and removed upstream. The learnt parity offset and
    /// the stationary reference move with them, so the removal neither raises a parity alarm nor
    /// spoils the reference. No allocation.
    pub fn subtract_channel_biases(&mut self, bias: &[f64; MAX_CHANNELS]) {
        if let Some(solver) = &self.solver {
            self.correction.shift(&self.geometry, solver, bias);
        }
        if let (Some(space), Some(offset)) = (&self.parity, self.offset.as_mut()) {
            let dim = space.dimension();
            let mut vb = [0.0; MAX_PARITY];
            space.parity(bias, &mut vb);
            let mut mean = *offset.mean();
            for (m, d) in mean.iter_mut().zip(vb).take(dim) {
                *m -= d;
            }
            offset.set_mean(mean);
        }
        self.reference.shift(bias);
    }

    /// Re-admits an excluded channel (explicit command only; see the module docs): it goes on
    /// probation, tested against the channels in service while it stays out of the solution, and
    /// rejoins once it passed ([`super::probation`]); when those have no solution to test it
    /// against, it returns at once (rebuilding the solver and parity space). `Ok(false)` when the
    /// channel was not excluded.
    pub fn readmit(&mut self, channel: usize) -> Result<bool, ReadmitError> {
        let n = self.geometry.n();
        if channel >= n {
            return Err(ReadmitError {
                sensor: self.sensor.name(),
                channel,
                n,
            });
        }
        if self.excluded[channel] == FaultReason::None {
            return Ok(false);
        }
        if self.start_probation(channel) {
            return Ok(true);
        }
        self.excluded[channel] = FaultReason::None;
        self.excluded_mask &= !(1 << channel);
        self.health.forget(channel);
        self.reconfigure();
        Ok(true)
    }

    /// Latches the exclusion of `channel` with `reason` (the first reason stays).
    fn exclude(&mut self, channel: usize, reason: FaultReason) {
        if self.excluded[channel] == FaultReason::None {
            self.excluded[channel] = reason;
            self.excluded_mask |= 1 << channel;
        }
    }

    /// Rebuilds the solver, parity space and threshold for the current active set and restarts
    /// the windows. The adaptive noise estimate carries its learnt excess over.
    fn reconfigure(&mut self) {
        let n = self.geometry.n();
        let mask = self.active_mask();
        let inflation = match (&self.adaptive, &self.parity) {
            (Some(a), Some(p)) => a.inflation_over(p.configured_covariance()),
            _ => 1.0,
        };
        let old_parity = self.parity;
        if let (Some(solver), Some(parity)) = (&self.solver, &self.parity) {
            self.correction.rebase(&self.geometry, solver, parity);
        }
        self.solver = WlsSolver::new(&self.geometry, mask, &self.variances[..n]).ok();
        self.parity = self
            .solver
            .and_then(|_| ParitySpace::new(&self.geometry, mask, &self.variances[..n]).ok());
        let dim = self.parity_dimension();
        self.threshold = if dim > 0 {
            self.settings.thresholds[dim]
        } else {
            f64::INFINITY
        };
        if let (Some(a), Some(p)) = (self.adaptive.as_mut(), self.parity.as_mut()) {
            let configured = *p.configured_covariance();
            a.seed(&configured, dim, inflation);
            p.set_noise_covariance(a.covariance());
        }
        if let Some(offset) = self.offset.as_mut() {
            offset.carry_over(old_parity.as_ref(), self.parity.as_ref());
        }
        self.persistence.reset();
        self.window.clear();
        self.mean_shift.clear();
        self.relearned = 0;
        self.episode = 0;
        self.reference.clear_recent();
    }

    /// `z` less the correction the solution is computed on (see [`solve_correction`]); what
    /// another estimator over the same channels must use.
    pub fn corrected(&self, z: &[f64; MAX_CHANNELS]) -> [f64; MAX_CHANNELS] {
        self.correction.apply(z)
    }

    /// Channels in service (bit i = channel i).
    pub fn active_mask(&self) -> u32 {
        self.geometry.full_mask() & !self.excluded_mask
    }

    /// Latched exclusion reason of `channel` (`None` when in service or out of range).
    pub fn exclusion(&self, channel: usize) -> FaultReason {
        self.excluded
            .get(channel)
            .copied()
            .unwrap_or(FaultReason::None)
    }

    /// Parity space of the active set (`None` below three channels).
    pub fn parity(&self) -> Option<&ParitySpace> {
        self.parity.as_ref()
    }

    /// Solver of the active set (`None` when it cannot be solved).
    pub fn solver(&self) -> Option<&WlsSolver> {
        self.solver.as_ref()
    }

    /// Parity dimension of the active set.
    pub fn parity_dimension(&self) -> usize {
        self.parity.map_or(0, |p| p.dimension())
    }

    /// Current detection threshold (infinite without parity).
    pub fn threshold(&self) -> f64 {
        self.threshold
    }

    /// Status of the last sample.
    pub fn status(&self) -> &SensorStatus {
        &self.status
    }

    /// The validated settings in use.
    pub fn settings(&self) -> &FdiSettings {
        &self.settings
    }

    /// The sensor type monitored.
    pub fn sensor(&self) -> SensorType {
        self.sensor
    }
}
