//! What kind of fix a UBX solution (NAV-PVT, NAV-SOL, HNR-PVT) is.
//!
//! The rule: a solution is published as what the receiver says it is, with the accuracies it
//! reports, and is never made to look better than that.
//! - gpsFix 0 (no fix) and 5 (time only: the receiver holds a surveyed or configured position
//!   and measures time, not position) are [`GnssFixType::NoFix`]; so are values the protocol does
//!   not define.
//! - gpsFix 1 (dead reckoning only) is [`GnssFixType::DeadReckoning`], 2 is
//!   [`GnssFixType::Fix2d`], 3 and 4 (GNSS with dead reckoning) [`GnssFixType::Fix3d`].
//! - Without the gnssFixOK flag (the solution is outside the receiver's accuracy or DOP masks,
//!   typically while it converges) the fix keeps its type and the receiver's own, large,
//!   accuracy estimates: the navigator's σ floors and gates decide what such a fix is worth.
//!   It is never upgraded: a differential or carrier-phase solution flag counts only with
//!   gnssFixOK set.
//! - With gnssFixOK, a three-dimensional fix is [`GnssFixType::RtkFixed`] or
//!   [`GnssFixType::RtkFloat`] by its carrier-phase solution, else
//!   [`GnssFixType::Differential`] when corrections were applied, else [`GnssFixType::Fix3d`].

use ipc_types::GnssFixType;

/// What the receiver's status fields say about one solution.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolutionStatus {
    /// The gpsFix field as sent (0..=5 defined).
    pub gps_fix: u8,
    /// gnssFixOK: the solution is within the receiver's accuracy and DOP masks.
    pub fix_ok: bool,
    /// diffSoln: differential corrections were applied.
    pub differential: bool,
    /// carrSoln: 0 none, 1 float ambiguities, 2 fixed ambiguities (NAV-PVT only).
    pub carrier: u8,
}

/// The fix type of a solution with status `s`; see the module documentation for the rule.
pub fn fix_type(s: SolutionStatus) -> GnssFixType {
    match s.gps_fix {
        1 => GnssFixType::DeadReckoning,
        2 => GnssFixType::Fix2d,
        3 | 4 if !s.fix_ok => GnssFixType::Fix3d,
        3 | 4 => match s.carrier {
            2 => GnssFixType::RtkFixed,
            1 => GnssFixType::RtkFloat,
            _ if s.differential => GnssFixType::Differential,
            _ => GnssFixType::Fix3d,
        },
        _ => GnssFixType::NoFix,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn status(gps_fix: u8, fix_ok: bool, differential: bool, carrier: u8) -> SolutionStatus {
        SolutionStatus {
            gps_fix,
            fix_ok,
            differential,
            carrier,
        }
    }

    #[test]
    fn time_only_and_no_fix_are_not_positions() {
        for gps_fix in [0, 5, 6, 255] {
            for fix_ok in [false, true] {
                assert_eq!(
                    fix_type(status(gps_fix, fix_ok, true, 2)),
                    GnssFixType::NoFix
                );
            }
        }
    }

    #[test]
    fn a_fix_outside_the_receivers_masks_keeps_its_type_but_is_never_upgraded() {
        for gps_fix in [3, 4] {
            for carrier in [0, 1, 2] {
                assert_eq!(
                    fix_type(status(gps_fix, false, true, carrier)),
                    GnssFixType::Fix3d
                );
            }
        }
        assert_eq!(fix_type(status(2, false, true, 2)), GnssFixType::Fix2d);
        assert_eq!(
            fix_type(status(1, false, false, 0)),
            GnssFixType::DeadReckoning
        );
    }

    #[test]
    fn a_fix_within_the_masks_is_what_its_solution_flags_say() {
        assert_eq!(fix_type(status(3, true, false, 0)), GnssFixType::Fix3d);
        assert_eq!(fix_type(status(4, true, false, 0)), GnssFixType::Fix3d);
        assert_eq!(
            fix_type(status(3, true, true, 0)),
            GnssFixType::Differential
        );
        assert_eq!(fix_type(status(3, true, true, 1)), GnssFixType::RtkFloat);
        assert_eq!(fix_type(status(3, true, false, 2)), GnssFixType::RtkFixed);
        assert_eq!(fix_type(status(2, true, true, 2)), GnssFixType::Fix2d);
    }
}
