//! Per-channel gyro bias from a start-up window at rest (docs/design.md §6.1; \[R3\] eq. 1).
//!
//! **Why per channel.** The navigator estimates a gyro bias on the fused body axes during its
//! static alignment: `b_body = G b`, with G the least-squares matrix of the channel set in use and
//! b the channel biases. When a channel is later excluded, the remaining channels' biases project
//! through another matrix G′, so the fused rate steps by `(G′ − G) b` — including the part of b that
//! the full set hid in the parity space — and the navigator's body-axis estimate no longer matches:
//! an attitude drift after every reconfiguration. Removing b channel by channel, before parity and
//! the solve, makes every channel set see (nearly) bias-free channels, so an exclusion does not step.
//!
//! **Window.** Over the first `window` samples the calibrated value of every gyro channel is
//! averaged, and the fused rate and specific force are judged by the stationary detector's own
//! criterion ([`crate::fdi::stationary`]: per-axis spread of rate and specific force, mean rate
//! below `max_rate`, every sample solvable) over that one window. The biases are accepted only when
//! the window was at rest and no channel's mean exceeds `max_rate` (a larger "bias" is a fault or
//! motion, not a turn-on bias); otherwise nothing is estimated and nothing is ever subtracted.
//! Channels not valid in every sample of the window get no bias (zero). From the sample after the
//! window on, the biases are subtracted from the calibrated values.
//!
//! **Earth rate.** At rest on the rotating Earth each gyro channel reads `h_i·ω_ie` (up to
//! 7.29e-5 rad/s on the fused axes) on top of its bias. The window mean cannot tell the two apart,
//! so the Earth-rate component seen at rest is removed as well — exactly what the navigator's
//! static alignment does with its body-axis bias — and the navigator's own bias estimate then comes
//! out ≈ 0. The removed Earth rate is only correct for the attitude held during the window; for a
//! MEMS-grade block (bias instability ≫ Earth rate) this is the usual, accepted approximation.
//!
//! Per sample this is a few additions per channel: no allocation.

use crate::fdi::stationary::{StationaryDetector, StationarySettings};
use crate::geometry::MAX_CHANNELS;

/// Where the start-up bias estimate stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RestBiasState {
    /// Disabled by configuration (`rest_bias_s = 0`).
    Disabled,
    /// The window is still being collected.
    Collecting,
    /// The window was at rest: the biases are being subtracted.
    Estimated,
    /// The window was not at rest (or a channel mean was implausible): no bias is subtracted.
    NotAtRest,
}

/// Per-channel bias estimate over a start-up window at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RestBias {
    window: u32,
    seen: u32,
    n: usize,
    /// Channels valid in every sample so far.
    present: u32,
    sum: [f64; MAX_CHANNELS],
    detector: StationaryDetector,
    max_rate: f64,
    bias: [f64; MAX_CHANNELS],
    state: RestBiasState,
}

impl RestBias {
    /// An estimate over the first `window` samples (0 disables it) of `n` channels, judged at rest
    /// by the stationary criterion `settings` applied to the whole window.
    pub fn new(window: u32, n: usize, settings: StationarySettings) -> Self {
        let n = n.min(MAX_CHANNELS);
        Self {
            window,
            seen: 0,
            n,
            present: crate::geometry::channel_mask(n),
            sum: [0.0; MAX_CHANNELS],
            detector: StationaryDetector::new(StationarySettings {
                window: window.max(1),
                ..settings
            }),
            max_rate: settings.max_rate,
            bias: [0.0; MAX_CHANNELS],
            state: if window == 0 {
                RestBiasState::Disabled
            } else {
                RestBiasState::Collecting
            },
        }
    }

    /// Collects the calibrated values `z` (channels in `valid`) while the window lasts; once the
    /// biases are estimated, subtracts them from `z` in place.
    pub fn apply(&mut self, z: &mut [f64; MAX_CHANNELS], valid: u32) {
        match self.state {
            RestBiasState::Collecting => {
                self.present &= valid;
                for (s, v) in self.sum.iter_mut().zip(z.iter()).take(self.n) {
                    *s += v;
                }
            }
            RestBiasState::Estimated => {
                for (v, b) in z.iter_mut().zip(&self.bias).take(self.n) {
                    *v -= b;
                }
            }
            RestBiasState::Disabled | RestBiasState::NotAtRest => {}
        }
    }

    /// Ends the sample with the fused `rate` and `force` (`ok`: both were solved). Returns the
    /// biases when this sample completed an at-rest window (they apply from the next sample on).
    pub fn end_sample(
        &mut self,
        rate: &[f64; 3],
        force: &[f64; 3],
        ok: bool,
    ) -> Option<&[f64; MAX_CHANNELS]> {
        if self.state != RestBiasState::Collecting {
            return None;
        }
        self.seen += 1;
        let at_rest = self.detector.push(rate, force, ok)?;
        let count = f64::from(self.seen);
        let mut bias = [0.0; MAX_CHANNELS];
        for (i, b) in bias.iter_mut().enumerate().take(self.n) {
            if self.present & (1 << i) != 0 {
                *b = self.sum[i] / count;
            }
        }
        let plausible = bias.iter().all(|b| b.abs() <= self.max_rate);
        if at_rest && plausible {
            self.bias = bias;
            self.state = RestBiasState::Estimated;
            Some(&self.bias)
        } else {
            self.state = RestBiasState::NotAtRest;
            None
        }
    }

    /// Where the estimate stands.
    pub fn state(&self) -> RestBiasState {
        self.state
    }

    /// The per-channel biases subtracted (N entries; zeros unless [`RestBiasState::Estimated`]).
    pub fn bias(&self) -> &[f64] {
        &self.bias[..self.n]
    }

    /// Window length, samples (0: disabled).
    pub fn window(&self) -> u32 {
        self.window
    }
}
