//! Isolation by the generalised likelihood test over the alarm episode.
//!
//! A single sample's GLT (see [`super::parity`]) is noisy: with faults of a few σ a wrong channel
//! wins a few percent of the time. Isolation therefore uses the evidence of the whole episode —
//! the samples since the first exceedance that led to the declaration, at most the last
//! [`MAX_EVIDENCE`]: for a constant bias f on channel i over L samples, twice the log-likelihood
//! ratio against "no fault", maximised over f, is
//!
//! ```text
//! g_i = (w_iᵀ Σp')² / (L · w_iᵀ w_i)
//! ```
//!
//! (the GLT of the summed whitened parity, whose noise grows like √L while the fault grows like
//! L), and `(g_i − g_j)/2` is the log-likelihood ratio of "fault on i" against "fault on j".
//! The winner is isolated only when it beats every channel with a different signature by
//! `margin` (default 10: a likelihood ratio of e⁵ ≈ 150); until then the fault is
//! detected-but-unisolated with the close contenders as candidates, and the evidence keeps
//! growing with every sample of the episode. Twins of the winner (parallel columns, e.g. every
//! channel when N = 4) can never be separated by parity; they stay candidates for the other
//! isolation paths.

use super::MAX_PARITY;
use super::parity::ParitySpace;
/// Most samples of evidence summed for isolation.
pub const MAX_EVIDENCE: usize = 16;
use crate::geometry::MAX_CHANNELS;

/// The whitened parity vectors of the last [`MAX_EVIDENCE`] samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ParityWindow {
    ring: [[f64; MAX_PARITY]; MAX_EVIDENCE],
    len: usize,
    pos: usize,
}

impl Default for ParityWindow {
    fn default() -> Self {
        Self {
            ring: [[0.0; MAX_PARITY]; MAX_EVIDENCE],
            len: 0,
            pos: 0,
        }
    }
}

impl ParityWindow {
    /// Adds one whitened parity vector.
    pub fn push(&mut self, pw: &[f64; MAX_PARITY]) {
        self.ring[self.pos] = *pw;
        self.pos = (self.pos + 1) % MAX_EVIDENCE;
        self.len = (self.len + 1).min(MAX_EVIDENCE);
    }

    /// Sum of the last `count` stored vectors (at most as many as stored; first `dim` entries)
    /// and how many were summed.
    pub fn sum_last(&self, count: usize, dim: usize) -> ([f64; MAX_PARITY], usize) {
        let count = count.min(self.len);
        let mut s = [0.0; MAX_PARITY];
        for back in 1..=count {
            let v = &self.ring[(self.pos + MAX_EVIDENCE - back) % MAX_EVIDENCE];
            for (a, b) in s.iter_mut().zip(v).take(dim) {
                *a += b;
            }
        }
        (s, count)
    }

    /// Forgets the stored vectors (after the active set changed).
    pub fn clear(&mut self) {
        self.len = 0;
        self.pos = 0;
    }
}

/// Outcome of isolating a declared parity fault.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParityIsolation {
    /// This channel explains the evidence better than every channel with another signature, by
    /// at least the margin.
    Channel(usize),
    /// These channels (bit mask) remain contenders: detected, not (yet) isolated by parity.
    Ambiguous(u32),
    /// No channel is visible to parity.
    Unobservable,
}

/// Isolates the fault behind the last `episode` samples of `window` (see the module docs).
pub fn isolate(
    space: &ParitySpace,
    window: &ParityWindow,
    episode: usize,
    margin: f64,
) -> ParityIsolation {
    let (sum, len) = window.sum_last(episode.max(1), space.dimension());
    isolate_sum(space, &sum, len as f64, margin)
}

/// Isolates the fault behind `sum`, the whitened parity summed over `len` samples (or a mean
/// scaled to the sum of its effective length): the same GLT as [`isolate`].
pub fn isolate_sum(
    space: &ParitySpace,
    sum: &[f64; MAX_PARITY],
    len: f64,
    margin: f64,
) -> ParityIsolation {
    let mut scores = [0.0; MAX_CHANNELS];
    let Some(best) = space.glt_scores(sum, &mut scores) else {
        return ParityIsolation::Unobservable;
    };
    let twins = space.twins(best);
    let scale = 1.0 / len.max(1.0);
    let best_score = scores[best] * scale;
    let contenders = (0..MAX_CHANNELS)
        .filter(|&j| space.twins(j) != 0 && scores[j] * scale > best_score - margin)
        .fold(twins, |m, j| m | 1 << j);
    if contenders == 1 << best {
        ParityIsolation::Channel(best)
    } else {
        ParityIsolation::Ambiguous(contenders)
    }
}
