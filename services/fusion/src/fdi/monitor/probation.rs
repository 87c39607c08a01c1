//! The probation side of the monitor: a channel re-admitted by command stays out of the solution
//! while it is tested against the channels in service, and rejoins only once it passed (see
//! [`crate::fdi::probation`]).

use super::{MonitorInput, SensorMonitor, bits};
use crate::fdi::channel_health::HealthFindings;
use crate::fdi::probation::ProbationVerdict;
use crate::geometry::MAX_CHANNELS;
use ipc_types::FaultReason;

impl SensorMonitor {
    /// Puts the excluded `channel` on probation; false when the channels in service have no
    /// solution to test it against (it then returns at once, as nothing better is left).
    pub(super) fn start_probation(&mut self, channel: usize) -> bool {
        if self.solver.is_none() {
            return false;
        }
        self.probation.start(channel);
        self.health.forget(channel);
        true
    }

    /// Channels whose health is judged on this sample: those in service and the valid ones on
    /// probation.
    pub(super) fn judged_mask(&self, valid: u32) -> u32 {
        self.active_mask() | (self.probation.channels() & valid)
    }

    /// One sample of the probation of every channel on it: the health verdicts `found` of this
    /// sample first, then its residual against the solution of the channels in service. A channel
    /// that passed rejoins (reconfiguration); one that failed stays excluded with the reason of
    /// the test it failed.
    pub(super) fn probation_step(&mut self, found: &HealthFindings, input: &MonitorInput) {
        let on = self.probation.channels();
        if on == 0 {
            return;
        }
        let Some(solver) = self.solver else {
            // The channels in service lost their solution: nothing to test against. The
            // candidates stay excluded; the recovery re-test takes them up with the others.
            for ch in bits(on) {
                self.probation.stop(ch);
            }
            return;
        };
        let z = self.correction.apply(input.z);
        let (x, _) = solver.solve(&z);
        let p = solver.covariance();
        let saturated = found.saturated & on;
        let in_range = if saturated != 0 {
            self.should_be_in_range(saturated, found.at_rail, input.z)
        } else {
            0
        };
        let mut passed = 0u32;
        for ch in bits(on) {
            let bit = 1u32 << ch;
            if self.excluded[ch] == FaultReason::None {
                // Returned another way (the recovery re-test): nothing left to decide.
                self.probation.stop(ch);
                continue;
            }
            let failed = if input.valid & bit == 0 {
                Some(FaultReason::Missing)
            } else if found.stuck & bit != 0 {
                Some(FaultReason::Stuck)
            } else if found.noisy & bit != 0 {
                Some(FaultReason::Noisy)
            } else if saturated & in_range & bit != 0 {
                Some(FaultReason::Saturated)
            } else {
                None
            };
            let verdict = match failed {
                Some(reason) => {
                    self.probation.stop(ch);
                    ProbationVerdict::Failed(reason)
                }
                // At a rail the value is unknown: no evidence either way.
                None if found.at_rail & bit != 0 => ProbationVerdict::Testing,
                None => {
                    let h = self.geometry.axes()[ch];
                    let r = z[ch] - (h[0] * x[0] + h[1] * x[1] + h[2] * x[2]);
                    let (variance, allowance) = self.residual_model(ch, &h, &p, &x);
                    self.probation.push(ch, r, variance, allowance)
                }
            };
            match verdict {
                ProbationVerdict::Testing => {}
                ProbationVerdict::Passed => passed |= bit,
                ProbationVerdict::Failed(reason) => self.excluded[ch] = reason,
            }
        }
        if passed != 0 {
            for ch in bits(passed) {
                self.excluded[ch] = FaultReason::None;
            }
            self.excluded_mask &= !passed;
            self.reconfigure();
        }
    }

    /// Model of the residual of channel `ch` (axis `h`) against a solution `x` of covariance `p`:
    /// its variance — the channel's noise, the reference's `hᵀ P h`, and the motion's share of both
    /// (the reference's scaled as its noise is, taking the candidate's σ as the block's) — and the
    /// allowance for the systematic disagreement declared in proportion to the motion, scaled the
    /// same way (see [`crate::fdi::probation`]).
    fn residual_model(
        &self,
        ch: usize,
        h: &[f64; 3],
        p: &[[f64; 3]; 3],
        x: &[f64; 3],
    ) -> (f64, f64) {
        let mut q = 0.0;
        for (hi, row) in h.iter().zip(p) {
            q += hi * (row[0] * h[0] + row[1] * h[1] + row[2] * h[2]);
        }
        let s2 = self.variances[ch];
        let amplification = if s2 > 0.0 { 1.0 + q / s2 } else { 1.0 };
        let variance = s2 + q + self.motion_variance * amplification;
        let norm = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        let allowance = self.settings.motion_noise_fraction * norm * amplification.sqrt();
        (variance, allowance)
    }

    /// `channel` is on probation: re-admitted by command, out of the solution until it passes.
    pub fn on_probation(&self, channel: usize) -> bool {
        channel < MAX_CHANNELS && self.probation.channels() & (1 << channel) != 0
    }

    /// Channels on probation (bit i = channel i).
    pub fn probation_mask(&self) -> u32 {
        self.probation.channels()
    }

    /// The probation's bias test of `channel` so far: |mean residual| in standard deviations of
    /// the mean, and the bound it must stay under (see [`crate::fdi::probation`]).
    pub fn probation_bias_score(&self, channel: usize) -> (f64, f64) {
        (self.probation.bias_score(channel), self.probation.bound())
    }
}
