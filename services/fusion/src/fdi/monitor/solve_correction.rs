//! The channel-bias correction subtracted before the least-squares solve, so that excluding a
//! channel does not step the fused value.
//!
//! **Why.** Residual channel biases β (what calibration and the start-up rest bias left, about
//! σ/√window per channel) reach the solution as `G β`. Excluding a channel swaps G for the reduced
//! set's G′, and since both invert H exactly (`G H = G′ H = I`), the solution steps by
//! `(G′ − G) β`: the part of β in the parity space, which the full set hid, is suddenly projected
//! into the output. The navigator had calibrated its own bias estimate against `G β`, so the step
//! shows as an attitude drift right after every reconfiguration.
//!
//! **What.** The monitor keeps the mean p̄ of the parity of the corrected values, `V (z − c)`: a
//! running mean of every fault-free sample (gated as the parity offset is, [`crate::fdi::offset`])
//! until it has the offset's window of them, then following at the offset's rate. At each
//! reconfiguration from set S the correction c takes it up as `(I − H G_S) Vᵀ_S p̄`. `G_S`
//! annihilates that vector, so the solution on S is unchanged, while the bias left in `z − c`
//! then lies in the column space of `H_S`, which every subset solves to the same value: the
//! reduced solution continues where the full one was. The mean then starts again from zero, with
//! the weight of the samples it had. A bias removed upstream (the rest bias) moves c by
//! `−(I − H G_S) b`, which leaves `V (z − c)` and the solution's continuity as they were, so the
//! mean keeps every sample since the start: with the rest bias learnt over the first second, the
//! correction at 15 s knows the residual from fifteen times as many samples as the window had.
//!
//! The parity test keeps its own, slower offset: a running mean after its learning phase would
//! absorb a small fault before it is declared. A fault too small to be declared does reach this
//! mean; when its channel is later excluded, the share it had there stays in the solution, as it
//! had been all along — the correction keeps the solution continuous, it does not undo what the
//! channel did before it was excluded.
//!
//! Updated per fault-free sample (one parity product), at reconfiguration and at bias removal;
//! no allocation.

use crate::fdi::MAX_PARITY;
use crate::fdi::offset::ParityOffset;
use crate::fdi::parity::ParitySpace;
use crate::geometry::{Geometry, MAX_CHANNELS};
use crate::wls::WlsSolver;

/// Per-channel values subtracted from the measurements before the solve (zero until the first
/// reconfiguration), and the parity mean they are built from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolveCorrection {
    channels: [f64; MAX_CHANNELS],
    /// Mean of `V (z − c)`; `None` when the parity offset is off (`parity_offset_window = 0`).
    mean: Option<ParityOffset>,
    /// Samples in the mean.
    seen: u64,
}

impl SolveCorrection {
    /// No correction yet; the mean follows at 1/`window` once it has `window` samples (the parity
    /// offset's window; 0 turns the correction off).
    pub fn new(window: u32) -> Self {
        Self {
            channels: [0.0; MAX_CHANNELS],
            mean: (window > 0).then(|| ParityOffset::new(window)),
            seen: 0,
        }
    }

    /// Adds a fault-free sample `z` of the set of `parity` to the mean.
    pub fn learn(&mut self, parity: &ParitySpace, z: &[f64; MAX_CHANNELS]) {
        let corrected = self.apply(z);
        let Some(mean) = self.mean.as_mut() else {
            return;
        };
        let mut p = [0.0; MAX_PARITY];
        parity.parity(&corrected, &mut p);
        // The running-mean gain until the window is reached, then the window's.
        mean.update(&p, &[0.0; 3], parity.dimension(), Some(self.seen), 0.0);
        self.seen = self.seen.saturating_add(1);
    }

    /// `z` minus the correction (entries of channels without a correction unchanged).
    pub fn apply(&self, z: &[f64; MAX_CHANNELS]) -> [f64; MAX_CHANNELS] {
        let mut out = *z;
        for (v, c) in out.iter_mut().zip(&self.channels) {
            *v -= c;
        }
        out
    }

    /// Before leaving the set of `solver` and `parity`: takes up the parity mean, which then
    /// starts again from zero.
    pub fn rebase(&mut self, geometry: &Geometry, solver: &WlsSolver, parity: &ParitySpace) {
        let Some(mean) = self.mean.as_mut() else {
            return;
        };
        if parity.dimension() == 0 {
            return;
        }
        let step = residual(geometry, solver, &parity.to_channels(mean.mean()));
        for (c, s) in self.channels.iter_mut().zip(step) {
            *c += s;
        }
        mean.set_mean([0.0; MAX_PARITY]);
    }

    /// The measurements will be shifted by `−bias` from the next sample on (a bias removed
    /// upstream while `solver`'s set is in use): the correction follows, leaving the solution on
    /// that set as the shift makes it.
    pub fn shift(&mut self, geometry: &Geometry, solver: &WlsSolver, bias: &[f64; MAX_CHANNELS]) {
        let step = residual(geometry, solver, bias);
        for (c, s) in self.channels.iter_mut().zip(step) {
            *c -= s;
        }
    }
}

/// `(I − H G) y` over the channels of `solver` (zero elsewhere): the part of `y` that the solver
/// does not see, in the form that every subset of its channels solves to the same value.
fn residual(
    geometry: &Geometry,
    solver: &WlsSolver,
    y: &[f64; MAX_CHANNELS],
) -> [f64; MAX_CHANNELS] {
    let (x, _) = solver.solve(y);
    let mut r = [0.0; MAX_CHANNELS];
    let mask = solver.mask();
    for (i, (ri, axis)) in r.iter_mut().zip(geometry.axes()).enumerate() {
        if mask & (1 << i) != 0 {
            *ri = y[i] - (axis[0] * x[0] + axis[1] * x[1] + axis[2] * x[2]);
        }
    }
    r
}
