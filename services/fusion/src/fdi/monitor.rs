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
//!    suspended during the learning phase at start); on a k-of-n declaration: the GLT over the
//!    alarm episode isolates and excludes the channel when it clearly wins (N_active ≥ 5, no
//!    twins; see [`super::isolation`]); otherwise, while stationary, the reference may isolate
//!    it among the contenders ([`super::stationary`]); otherwise the candidates are Suspect, the
//!    fault is reported as detected-not-isolated, and every channel stays in the solution;
//! 4. weighted least squares over the active set.
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

use super::MAX_PARITY;
use super::channel_health::{COUNT_MAX, COUNT_MIN, ChannelHealth, HealthFindings};
use super::config::{FdiSettings, ParityNoise, ReadmitPolicy};
use super::isolation::{self, ParityIsolation, ParityWindow};
use super::noise_estimate::AdaptiveParityNoise;
use super::offset::ParityOffset;
use super::parity::ParitySpace;
use super::persistence::Persistence;
use super::recovery::{ExclusionRetest, RetestInput};
use super::report::{ChannelEvents, SensorStatus};
use super::stationary::ChannelReference;
use crate::geometry::{Geometry, MAX_CHANNELS};
use crate::wls::WlsSolver;
use ipc_types::{ChannelState, FaultReason, SensorType};

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
    pub sensor: &'static str,
    pub channel: usize,
    pub n: usize,
}

/// What the parity test of one sample concluded.
struct ParityOutcome {
    t: f64,
    dim: usize,
    /// Suspects of a detected-but-unisolated fault.
    candidates: u32,
    learning: bool,
}

/// What the health checks and the recovery re-test decided on one sample, for the status.
struct HealthOutcome {
    /// Channels Suspect for a genuine over-range.
    saturated_suspect: u32,
    block_saturated: bool,
    auto_readmitted: u32,
}

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
    /// The learnt parity offset in channel terms, as of the last parity space that had one: it
    /// outlives a loss of the parity space (fewer than four channels) and is carried into the next.
    channel_offset: [f64; MAX_CHANNELS],
    /// Re-test of the exclusions while the type has no solution.
    retest: ExclusionRetest,
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
        let offset = (settings.parity_offset_window > 0)
            .then(|| ParityOffset::new(settings.parity_offset_window));
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
            health,
            noisy_suspect: 0,
            adaptive,
            offset,
            seen: 0,
            reference: ChannelReference::new(
                settings.stationary.window,
                settings.persistence_n as usize,
                sensor == SensorType::Gyro,
            ),
            status,
            last_x: [0.0; 3],
            motion_variance: 0.0,
            channel_offset: [0.0; MAX_CHANNELS],
            retest: ExclusionRetest::default(),
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
        let found = self.health.check(input.counts, z, self.active_mask());
        let saturated_suspect = self.apply_health(&found, z);
        if self.excluded_mask != before {
            self.reconfigure();
        }
        let active = self.active_mask();
        let health = HealthOutcome {
            saturated_suspect,
            block_saturated: active.count_ones() >= 3 && (active & !found.at_rail).count_ones() < 3,
            auto_readmitted: self.retest_exclusions(input),
        };

        // The solution before the test sets the motion's share of the noise for this sample.
        let before_test = self.solver.as_ref().map(|s| (s.mask(), s.solve(z)));
        if let Some((_, (x, _))) = &before_test {
            self.motion_variance = motion_variance(&self.settings, x, &self.last_x);
        }
        let (t, candidates, learning) = self.parity_test(z, stationary);

        let estimate = match &self.solver {
            Some(solver) => {
                let (x, var) = match before_test {
                    Some((mask, solution)) if mask == solver.mask() => solution,
                    _ => solver.solve(z),
                };
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

    /// Health verdicts → exclusions; returns the channels Suspect for a genuine over-range.
    fn apply_health(&mut self, found: &HealthFindings, z: &[f64; MAX_CHANNELS]) -> u32 {
        for ch in bits(found.stuck & self.active_mask()) {
            self.exclude(ch, FaultReason::Stuck);
        }
        if found.noise_verdict {
            self.noisy_suspect = 0;
        }
        for ch in bits(found.noisy & self.active_mask()) {
            // A noisy channel is still unbiased: with three left it is better than no solution.
            if self.active_mask().count_ones() > 3 {
                self.exclude(ch, FaultReason::Noisy);
            } else {
                self.noisy_suspect |= 1 << ch;
            }
        }
        let saturated = found.saturated & self.active_mask();
        if saturated == 0 {
            return 0;
        }
        let in_range = self.should_be_in_range(saturated, found.at_rail, z);
        for ch in bits(saturated & in_range) {
            self.exclude(ch, FaultReason::Saturated);
        }
        saturated & !in_range
    }

    /// Of the `saturated` channels, those that the active channels not at a rail place well
    /// inside the converter range (inner 90 %): a channel at a rail there is faulty, not
    /// over-ranged. Needs three channels off the rails; without them nothing can be said.
    fn should_be_in_range(&self, saturated: u32, at_rail: u32, z: &[f64; MAX_CHANNELS]) -> u32 {
        let others = self.active_mask() & !at_rail;
        let n = self.geometry.n();
        if others.count_ones() < 3 {
            return 0;
        }
        let Ok(solver) = WlsSolver::new(&self.geometry, others, &self.variances[..n]) else {
            return 0;
        };
        let (x, _) = solver.solve(z);
        let axes = self.geometry.axes();
        bits(saturated)
            .filter(|&ch| {
                let h = axes[ch];
                let predicted = h[0] * x[0] + h[1] * x[1] + h[2] * x[2];
                let [lo, hi] = self.rail_values[ch];
                let margin = 0.05 * (hi - lo);
                predicted > lo + margin && predicted < hi - margin
            })
            .fold(0, |m, ch| m | 1 << ch)
    }

    /// Parity test, persistence, adaptive noise and isolation. Returns the test statistic, the
    /// Suspect candidates of a detected-but-unisolated fault (0 when none) and whether the
    /// adaptive estimate was still learning (declarations suspended).
    fn parity_test(&mut self, z: &[f64; MAX_CHANNELS], stationary: bool) -> (f64, u32, bool) {
        let active = self.active_mask();
        let Some(space) = self.parity.as_mut().filter(|p| p.dimension() > 0) else {
            self.reference.push(z, active, 0.0, true);
            return (0.0, 0, false);
        };
        let dim = space.dimension();
        let learning_seen =
            (self.seen < u64::from(self.settings.learning_samples)).then_some(self.seen);
        let learning = learning_seen.is_some();
        self.seen = self.seen.saturating_add(1);
        let mut p = [0.0; MAX_PARITY];
        space.parity(z, &mut p);
        let raw = p;
        if let Some(offset) = &self.offset {
            for (v, m) in p.iter_mut().zip(offset.mean()).take(dim) {
                *v -= m;
            }
        }
        // The motion's share of the channel noise inflates the parity noise uniformly (V has
        // orthonormal rows); the test and the estimates see the parity scaled back to the
        // motion-free noise, so the adaptive estimate does not learn the manoeuvres.
        let base = space.mean_noise_variance();
        let inflation = if base > 0.0 {
            1.0 + self.motion_variance / base
        } else {
            1.0
        };
        let scale = inflation.sqrt().recip();
        p.iter_mut().take(dim).for_each(|v| *v *= scale);
        let mut pw = [0.0; MAX_PARITY];
        let t = space.whiten(&p, &mut pw);
        let exceeded = t > self.threshold;
        self.window.push(&pw);
        let persistent = self.persistence.push(exceeded);
        self.episode = if self.persistence.count() > 0 {
            self.episode + 1
        } else {
            0
        };
        // The estimates learn from every sample while learning, afterwards only while no sample
        // of the window exceeded: a fault must become neither "offset" nor "noise".
        if learning || self.persistence.count() == 0 {
            if let Some(offset) = self.offset.as_mut() {
                offset.update(&raw, dim, learning_seen);
            }
            let truncation = self.settings.truncation[dim];
            if let Some(estimate) = self.adaptive.as_mut()
                && estimate.update(&p, learning_seen, truncation)
            {
                space.set_noise_covariance(estimate.covariance());
            }
        }
        let declared = persistent && !learning;
        self.reference.push(z, active, t, !declared);
        if !declared {
            return (t, 0, learning);
        }
        let isolation = isolation::isolate(
            space,
            &self.window,
            self.episode,
            self.settings.isolation_margin,
        );
        let candidates = match isolation {
            ParityIsolation::Channel(ch) => {
                self.exclude(ch, FaultReason::Parity);
                self.reconfigure();
                return (t, 0, false);
            }
            ParityIsolation::Ambiguous(twins) => twins,
            ParityIsolation::Unobservable => active,
        };
        if stationary
            && let Some(ch) = self.reference.isolate(
                candidates,
                active,
                &self.variances,
                self.settings.reference_ratio,
            )
        {
            self.exclude(ch, FaultReason::StationaryReference);
            self.reconfigure();
            return (t, 0, false);
        }
        (t, candidates, false)
    }

    fn build_status(
        &self,
        parity: &ParityOutcome,
        health: &HealthOutcome,
        input: &MonitorInput,
    ) -> SensorStatus {
        let saturated_suspect = health.saturated_suspect;
        let n = self.geometry.n();
        let candidates = parity.candidates;
        let mut status = SensorStatus {
            n,
            test_statistic: parity.t,
            threshold: self.threshold,
            parity_dimension: parity.dim,
            detected_not_isolated: candidates != 0,
            device_error: input.device_error,
            learning: parity.learning,
            block_saturated: health.block_saturated,
            auto_readmitted: health.auto_readmitted,
            ..SensorStatus::ABSENT
        };
        for i in 0..n {
            let bit = 1u32 << i;
            let (state, reason) = if self.excluded[i] != FaultReason::None {
                (ChannelState::Excluded, self.excluded[i])
            } else {
                let reason = if candidates & bit != 0 {
                    FaultReason::Parity
                } else if saturated_suspect & bit != 0 {
                    FaultReason::Saturated
                } else if self.noisy_suspect & bit != 0 {
                    FaultReason::Noisy
                } else if input.temperature_suspect & bit != 0 {
                    FaultReason::Temperature
                } else if input.device_error {
                    FaultReason::DeviceError
                } else {
                    FaultReason::None
                };
                if reason == FaultReason::None {
                    (ChannelState::Ok, reason)
                } else {
                    (ChannelState::Suspect, reason)
                }
            };
            status.states[i] = state;
            status.reasons[i] = reason;
        }
        status
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

    /// Returns an excluded channel to service (explicit command only; see the module docs).
    /// `Ok(false)` when the channel was not excluded. Rebuilds the solver and parity space.
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
        self.excluded[channel] = FaultReason::None;
        self.excluded_mask &= !(1 << channel);
        self.health.forget(channel);
        self.reconfigure();
        Ok(true)
    }

    /// The recovery re-test (see [`super::recovery`]): while the type has no solution and the
    /// policy allows, excluded channels that are valid, off the rails, varying and consistent with
    /// the others for `readmit_after_samples` in a row return. Returns the channels re-admitted.
    fn retest_exclusions(&mut self, input: &MonitorInput) -> u32 {
        if self.solver.is_some() || self.settings.readmit == ReadmitPolicy::Operator {
            self.retest.clear();
            return 0;
        }
        let n = self.geometry.n();
        let off_rail = (0..n)
            .filter(|&i| {
                input
                    .counts
                    .get(i)
                    .is_some_and(|&c| c != COUNT_MIN && c != COUNT_MAX)
            })
            .fold(0u32, |m, i| m | 1 << i);
        let candidates = self.active_mask() | (self.excluded_mask & input.valid & off_rail);
        let mut z = *input.z;
        for (v, offset) in z.iter_mut().zip(&self.channel_offset).take(n) {
            *v -= offset;
        }
        let retest = RetestInput {
            candidates,
            counts: input.counts,
            z: &z,
        };
        let Some(back) = self.retest.push(
            &self.geometry,
            &self.variances,
            &self.settings.thresholds,
            (self.settings.persistence_k, self.settings.persistence_n),
            &retest,
            self.settings.readmit_after_samples,
        ) else {
            return 0;
        };
        let returned = back & self.excluded_mask;
        for ch in bits(returned) {
            self.excluded[ch] = FaultReason::None;
            self.health.forget(ch);
        }
        self.excluded_mask &= !returned;
        self.reconfigure();
        self.retest.clear();
        returned
    }

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
            // Through channel terms, so that the offset also survives a spell without parity.
            if let Some(old) = &old_parity {
                self.channel_offset = old.to_channels(offset.mean());
            }
            let mut carried = [0.0; MAX_PARITY];
            if let Some(new) = &self.parity {
                new.parity(&self.channel_offset, &mut carried);
            }
            offset.set_mean(carried);
        }
        self.persistence.reset();
        self.window.clear();
        self.episode = 0;
        self.reference.clear_recent();
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

/// Channel variance added by the motion: `(f·|x|)² + (τ·|x − x_prev|)²`, τ in samples.
fn motion_variance(settings: &FdiSettings, x: &[f64; 3], last: &[f64; 3]) -> f64 {
    let norm2 = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>();
    let f = settings.motion_noise_fraction;
    let tau = settings.timing_skew_samples;
    if f == 0.0 && tau == 0.0 {
        return 0.0;
    }
    let change = [x[0] - last[0], x[1] - last[1], x[2] - last[2]];
    f * f * norm2(*x) + tau * tau * norm2(change)
}
