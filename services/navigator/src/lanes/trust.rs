//! Whether a lane's solution may be chosen for its quality: the selector leaves a lane for the
//! other only towards a trusted solution, and the navigator copies only a trusted peer when it
//! takes over.

use ipc_types::{NavMode, NavState};

/// Why a solution is not trusted ([`distrust`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distrust {
    /// Still aligning.
    Aligning,
    /// Its mode is invalid (or a mode this build cannot read).
    Invalid,
    /// Its solution has run only this many samples (since alignment or takeover).
    Young {
        /// Samples since the solution started (0: no start recorded).
        run: u64,
    },
    /// Its attitude is not finite.
    NonFinite,
}

impl Distrust {
    /// One word or two, for logs and one-line messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Aligning => "aligning",
            Self::Invalid => "invalid",
            Self::Young { .. } => "too young",
            Self::NonFinite => "non-finite",
        }
    }
}

/// Why `s` is not a solution the selector may choose for quality; `None` when it is.
pub fn distrust(s: &NavState, settle: u64) -> Option<Distrust> {
    let run = s.header.origin_seq.saturating_sub(s.solution_start_seq);
    match NavMode::from_u8(s.mode) {
        Some(NavMode::Aligning) => Some(Distrust::Aligning),
        Some(m) if !m.is_usable() => Some(Distrust::Invalid),
        None => Some(Distrust::Invalid),
        Some(_) if s.solution_start_seq == 0 => Some(Distrust::Young { run: 0 }),
        Some(_) if run < settle => Some(Distrust::Young { run }),
        Some(_) if !s.quaternion.iter().all(|q| q.is_finite()) => Some(Distrust::NonFinite),
        Some(_) => None,
    }
}

/// A solution the selector may choose for quality.
pub fn trusted(s: &NavState, settle: u64) -> bool {
    distrust(s, settle).is_none()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lanes::test_samples::{SETTLE, aligning, nav};

    #[test]
    fn only_a_settled_usable_mode_is_trusted() {
        let settled = nav(0, 1 + SETTLE, 1);
        assert!(trusted(&settled, SETTLE));
        let coasting = NavState {
            mode: NavMode::Coasting as u8,
            ..settled
        };
        assert!(trusted(&coasting, SETTLE));
        // Aligning, invalid, or a mode this build cannot read: no usable solution.
        for mode in [NavMode::Aligning as u8, NavMode::Invalid as u8, 4, u8::MAX] {
            assert!(
                !trusted(&NavState { mode, ..settled }, SETTLE),
                "mode {mode}"
            );
        }
        assert!(!trusted(&nav(0, SETTLE, 1), SETTLE));
    }

    #[test]
    fn every_distrust_is_named_and_reported() {
        let settled = nav(0, 1 + SETTLE, 1);
        assert_eq!(distrust(&settled, SETTLE), None);
        let cases = [
            (aligning(0, 500), Distrust::Aligning),
            (
                NavState {
                    mode: NavMode::Invalid as u8,
                    ..settled
                },
                Distrust::Invalid,
            ),
            (NavState { mode: 4, ..settled }, Distrust::Invalid),
            (nav(0, 130, 100), Distrust::Young { run: 30 }),
            (nav(0, 130, 0), Distrust::Young { run: 0 }),
            (
                NavState {
                    quaternion: [f64::NAN, 0.0, 0.0, 0.0],
                    ..settled
                },
                Distrust::NonFinite,
            ),
        ];
        for (s, want) in cases {
            assert_eq!(distrust(&s, SETTLE), Some(want), "{s:?}");
        }
    }
}
