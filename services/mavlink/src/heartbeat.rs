//! HEARTBEAT: who is speaking. On board, rins is an onboard controller with no autopilot of its
//! own, so no autopilot or ground station mistakes it for the vehicle. On a bench, the `display`
//! profile presents it as a vehicle so that a ground station draws the solution — never beside a
//! real autopilot, which a second "vehicle" on the link would confuse.

use ipc_types::{Integrity, NavMode, NavState};

use crate::dialect::{HEARTBEAT_DATA, MavAutopilot, MavModeFlag, MavState, MavType};

/// How rins presents itself.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Profile {
    /// An onboard controller (`MAV_TYPE_ONBOARD_CONTROLLER`, `MAV_AUTOPILOT_INVALID`).
    Onboard,
    /// A vehicle of `vehicle` type for a ground station on a bench (`MAV_AUTOPILOT_GENERIC`;
    /// component id 1 by convention).
    Display {
        /// The vehicle type shown.
        vehicle: MavType,
    },
}

/// The system state a heartbeat reports for `nav`: booting while aligning, active while the
/// solution is usable and its integrity not invalid, critical otherwise; uninitialised before any
/// solution.
pub fn system_status(nav: Option<&NavState>) -> MavState {
    let Some(nav) = nav else {
        return MavState::MAV_STATE_UNINIT;
    };
    let invalid = Integrity::from_u8(nav.integrity).is_none_or(|i| i == Integrity::Invalid);
    match NavMode::from_u8(nav.mode) {
        Some(NavMode::Aligning) => MavState::MAV_STATE_BOOT,
        Some(m) if m.is_usable() && !invalid => MavState::MAV_STATE_ACTIVE,
        _ => MavState::MAV_STATE_CRITICAL,
    }
}

/// The heartbeat of `profile` for the latest solution `nav`.
pub fn heartbeat(profile: Profile, nav: Option<&NavState>) -> HEARTBEAT_DATA {
    let (mavtype, autopilot) = match profile {
        Profile::Onboard => (
            MavType::MAV_TYPE_ONBOARD_CONTROLLER,
            MavAutopilot::MAV_AUTOPILOT_INVALID,
        ),
        Profile::Display { vehicle } => (vehicle, MavAutopilot::MAV_AUTOPILOT_GENERIC),
    };
    HEARTBEAT_DATA {
        custom_mode: 0,
        mavtype,
        autopilot,
        base_mode: MavModeFlag::empty(),
        system_status: system_status(nav),
        mavlink_version: 3,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn onboard_is_no_autopilot_and_display_is_a_generic_vehicle() {
        let h = heartbeat(Profile::Onboard, None);
        assert_eq!(h.mavtype, MavType::MAV_TYPE_ONBOARD_CONTROLLER);
        assert_eq!(h.autopilot, MavAutopilot::MAV_AUTOPILOT_INVALID);
        assert_eq!(h.system_status, MavState::MAV_STATE_UNINIT);
        let d = heartbeat(
            Profile::Display {
                vehicle: MavType::MAV_TYPE_QUADROTOR,
            },
            None,
        );
        assert_eq!(
            (d.mavtype, d.autopilot),
            (
                MavType::MAV_TYPE_QUADROTOR,
                MavAutopilot::MAV_AUTOPILOT_GENERIC
            )
        );
    }

    #[test]
    fn the_state_follows_the_mode_and_integrity() {
        let nav = NavState::default();
        assert_eq!(system_status(Some(&nav)), MavState::MAV_STATE_BOOT);
        let navigating = NavState {
            mode: NavMode::Navigating as u8,
            ..nav
        };
        assert_eq!(system_status(Some(&navigating)), MavState::MAV_STATE_ACTIVE);
        let invalid = NavState {
            integrity: Integrity::Invalid as u8,
            ..navigating
        };
        assert_eq!(system_status(Some(&invalid)), MavState::MAV_STATE_CRITICAL);
        let unknown = NavState {
            mode: 50,
            ..navigating
        };
        assert_eq!(system_status(Some(&unknown)), MavState::MAV_STATE_CRITICAL);
    }
}
