//! Navigation samples for the lane module's tests.

use ipc_types::{NavMode, NavState};

/// The settling time of the tests' selector, samples.
pub const SETTLE: u64 = 100;

/// A navigating solution of `lane` at `seq` that started at `start`.
pub fn nav(lane: u8, seq: u64, start: u64) -> NavState {
    let mut s = NavState {
        mode: NavMode::Navigating as u8,
        lane,
        solution_start_seq: start,
        ..NavState::default()
    };
    s.header.origin_seq = seq;
    s
}

/// An aligning solution of `lane` at `seq` (no solution start yet).
pub fn aligning(lane: u8, seq: u64) -> NavState {
    let mut s = nav(lane, seq, 0);
    s.mode = NavMode::Aligning as u8;
    s
}
