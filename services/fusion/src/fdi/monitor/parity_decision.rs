//! The parity side of the monitor: the offset-corrected, motion-scaled parity test with its
//! persistence and its windowed mean, the adaptive noise and offset estimates it feeds, and the isolation of a declared
//! fault by the GLT or the stationary reference.

use super::SensorMonitor;
use crate::fdi::MAX_PARITY;
use crate::fdi::config::FdiSettings;
use crate::fdi::isolation::{self, ParityIsolation};
use crate::geometry::MAX_CHANNELS;
use ipc_types::FaultReason;

impl SensorMonitor {
    /// Parity test, persistence, adaptive noise and isolation. Returns the test statistic, the
    /// Suspect candidates of a detected-but-unisolated fault (0 when none) and whether the
    /// adaptive estimate was still learning (declarations suspended).
    pub(super) fn parity_test(
        &mut self,
        z: &[f64; MAX_CHANNELS],
        stationary: bool,
    ) -> (f64, u32, bool) {
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
        // After the active set changed the offset re-learns from scratch, and the windowed mean
        // waits for it: the offset carried over holds what the channels' biases were before the
        // change (a channel re-admitted after a fault came back with its own), and the windowed
        // mean would read that difference as a fault — and, declared, it stops the offset from
        // learning it, for ever. A re-admitted channel passed its probation against the others
        // first, and the per-sample test keeps watching meanwhile.
        let relearn_seen =
            (self.relearned < u64::from(self.settings.learning_samples)).then_some(self.relearned);
        self.relearned = self.relearned.saturating_add(1);
        let offset_seen = learning_seen.or(relearn_seen);
        let mut p = [0.0; MAX_PARITY];
        space.parity(z, &mut p);
        let raw = p;
        if let Some(offset) = &self.offset {
            for (v, m) in p.iter_mut().zip(offset.at(&self.test_x, dim)).take(dim) {
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
        let shifted = self.mean_shift.push(&pw, dim) > self.settings.mean_shift_thresholds[dim]
            && relearn_seen.is_none();
        self.episode = if self.persistence.count() > 0 {
            self.episode + 1
        } else {
            0
        };
        // The estimates learn from every sample while learning, afterwards only while no sample
        // of the window exceeded and the windowed mean is quiet: a fault must become neither
        // "offset" nor "noise".
        if learning || (self.persistence.count() == 0 && !shifted) {
            if let Some(offset) = self.offset.as_mut() {
                let noise = space.mean_noise_variance();
                offset.update(&raw, &self.test_x, dim, offset_seen, noise);
            }
            self.correction.learn(space, z);
            let truncation = self.settings.truncation[dim];
            if let Some(estimate) = self.adaptive.as_mut()
                && estimate.update(&p, learning_seen, truncation)
            {
                space.set_noise_covariance(estimate.covariance());
            }
        }
        let declared = (persistent || shifted) && !learning;
        self.reference.push(z, active, t, !declared);
        if !declared {
            return (t, 0, learning);
        }
        let isolation = if persistent {
            isolation::isolate(
                space,
                &self.window,
                self.episode,
                self.settings.isolation_margin,
            )
        } else {
            // The windowed mean is the evidence: as a sum over its effective length.
            let len = self.mean_shift.effective_len();
            let sum = self.mean_shift.mean().map(|m| m * len);
            isolation::isolate_sum(space, &sum, len, self.settings.isolation_margin)
        };
        let candidates = match isolation {
            ParityIsolation::Channel(ch) => {
                self.exclude(ch, FaultReason::Parity);
                self.reconfigure();
                return (t, 0, false);
            }
            ParityIsolation::Ambiguous(twins) => twins,
            ParityIsolation::Unobservable => active,
        };
        // The stationary reference weighs as much evidence as the declaration did: the last few
        // samples (the persistence window) for a fault the per-sample test declares; for one only
        // the windowed mean sees, each channel's mean over the same window — on a few samples a
        // channel's noise would pass for such a fault (a 1σ ramp on one gyro had another
        // excluded).
        let reference = &self.reference;
        let (variances, ratio) = (&self.variances, self.settings.reference_ratio);
        let found = stationary.then(|| {
            if persistent {
                reference.isolate(candidates, active, variances, ratio)
            } else {
                reference.isolate_smoothed(candidates, active, variances, ratio)
            }
        });
        if let Some(Some(ch)) = found {
            self.exclude(ch, FaultReason::StationaryReference);
            self.reconfigure();
            return (t, 0, false);
        }
        (t, candidates, false)
    }
}

/// Channel variance added by the motion: `(f·|x|)² + (τ·|x − x_prev|)²`, τ in samples.
pub(super) fn motion_variance(settings: &FdiSettings, x: &[f64; 3], last: &[f64; 3]) -> f64 {
    let norm2 = |v: [f64; 3]| v.iter().map(|c| c * c).sum::<f64>();
    let f = settings.motion_noise_fraction;
    let tau = settings.timing_skew_samples;
    if f == 0.0 && tau == 0.0 {
        return 0.0;
    }
    let change = [x[0] - last[0], x[1] - last[1], x[2] - last[2]];
    f * f * norm2(*x) + tau * tau * norm2(change)
}
