//! The channel-health side of the monitor: stuck, noisy and saturated verdicts turned into
//! exclusions (or Suspect states), and the re-test that returns excluded channels once the sensor
//! type has lost its solution (see [`crate::fdi::recovery`]).

use super::{MonitorInput, SensorMonitor, bits};
use crate::fdi::channel_health::HealthFindings;
use crate::fdi::config::ReadmitPolicy;
use crate::fdi::recovery::RetestInput;
use crate::geometry::MAX_CHANNELS;
use crate::wls::WlsSolver;
use ipc_types::FaultReason;

impl SensorMonitor {
    /// Health verdicts → exclusions; returns the channels Suspect for a genuine over-range.
    pub(super) fn apply_health(&mut self, found: &HealthFindings, z: &[f64; MAX_CHANNELS]) -> u32 {
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
    pub(super) fn should_be_in_range(
        &self,
        saturated: u32,
        at_rail: u32,
        z: &[f64; MAX_CHANNELS],
    ) -> u32 {
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

    /// The recovery re-test (see [`crate::fdi::recovery`]): while the type has no solution and the
    /// policy allows, excluded channels that are valid, off the rails, varying and consistent with
    /// the others for `readmit_after_samples` in a row return. Returns the channels re-admitted.
    pub(super) fn retest_exclusions(&mut self, input: &MonitorInput) -> u32 {
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
                    .is_some_and(|&c| !self.settings.health.rails.contains(&c))
            })
            .fold(0u32, |m, i| m | 1 << i);
        let candidates = self.active_mask() | (self.excluded_mask & input.valid & off_rail);
        let mut z = *input.z;
        let none = [0.0; MAX_CHANNELS];
        let channel_offset = self.offset.as_ref().map_or(&none, |o| o.channel_mean());
        for (v, offset) in z.iter_mut().zip(channel_offset).take(n) {
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
}
