//! The local frame's origin and its announcement to the autopilot.
//!
//! LOCAL_POSITION_NED and ODOMETRY give positions from an origin: the first shown solution's
//! position. An autopilot that fuses them as a local source must place that origin on the globe
//! with the same point, or its global position is off by the difference: rins tells it once when
//! the origin becomes known, again when it moves, and every [`ANNOUNCE_INTERVAL_NS`] so that an
//! autopilot started (or restarted) later still learns it. PX4 takes the SET_GPS_GLOBAL_ORIGIN
//! message; ArduPilot warns about that message from 4.8 on and drops it from 4.10, and takes the
//! COMMAND_INT `MAV_CMD_DO_SET_GLOBAL_ORIGIN` that replaces it ([`OriginForm`]).
//!
//! An origin is known only from a solution whose horizontal position is known: with no initial
//! position configured, the navigator's latitude and longitude are placeholders until a GNSS fix
//! (`POSITION_UNKNOWN`). The frame still starts at the first shown solution, so that the local
//! streams run, and moves to the first solution with a known position; a moved origin is a jump of
//! every local position, so the caller counts it as a reset of the estimate.

// SET_GPS_GLOBAL_ORIGIN is marked superseded by MAV_CMD_DO_SET_GLOBAL_ORIGIN, but PX4's receiver
// takes only the message.
#![allow(deprecated)]

use ipc_types::NavState;
pub use rins_navigator::consumer_origin::{OriginChange, OriginTracker, position_known};

use crate::dialect::{COMMAND_INT_DATA, MavCmd, MavFrame, MavMessage, SET_GPS_GLOBAL_ORIGIN_DATA};
use crate::local_frame::LocalOrigin;
use crate::time_usec;

/// How often the origin is announced again while it stays the same, ns.
pub const ANNOUNCE_INTERVAL_NS: u64 = 10_000_000_000;

/// `value × scale` rounded, within the range of an `i32` (a value out of it, or not finite, is no
/// origin to announce).
fn scaled_i32(value: f64, scale: f64) -> Option<i32> {
    let v = (value * scale).round();
    (v.is_finite() && v >= f64::from(i32::MIN) && v <= f64::from(i32::MAX)).then_some(v as i32)
}

/// SET_GPS_GLOBAL_ORIGIN for `origin` (WGS84 degrees ×1e7, altitude above mean sea level in mm),
/// addressed to `target_system`, stamped with `time_usec`; `None` for an origin the message
/// cannot carry.
pub fn set_gps_global_origin(
    origin: &LocalOrigin,
    target_system: u8,
    time_usec: u64,
) -> Option<SET_GPS_GLOBAL_ORIGIN_DATA> {
    Some(SET_GPS_GLOBAL_ORIGIN_DATA {
        latitude: scaled_i32(origin.latitude_rad.to_degrees(), 1e7)?,
        longitude: scaled_i32(origin.longitude_rad.to_degrees(), 1e7)?,
        altitude: scaled_i32(origin.altitude_m, 1e3)?,
        target_system,
        time_usec,
    })
}

/// The component id of an autopilot (MAV_COMP_ID_AUTOPILOT1): where the origin command goes.
pub const AUTOPILOT_COMPONENT: u8 = 1;

/// COMMAND_INT `MAV_CMD_DO_SET_GLOBAL_ORIGIN` for `origin` (WGS84 degrees ×1e7 in `x` and `y`,
/// altitude above mean sea level in m in `z`, frame `MAV_FRAME_GLOBAL`), addressed to the
/// autopilot of `target_system`; `None` for an origin the command cannot carry.
pub fn do_set_global_origin(origin: &LocalOrigin, target_system: u8) -> Option<COMMAND_INT_DATA> {
    let altitude = origin.altitude_m as f32;
    if !altitude.is_finite() {
        return None;
    }
    Some(COMMAND_INT_DATA {
        x: scaled_i32(origin.latitude_rad.to_degrees(), 1e7)?,
        y: scaled_i32(origin.longitude_rad.to_degrees(), 1e7)?,
        z: altitude,
        command: MavCmd::MAV_CMD_DO_SET_GLOBAL_ORIGIN,
        target_system,
        target_component: AUTOPILOT_COMPONENT,
        frame: MavFrame::MAV_FRAME_GLOBAL,
        ..COMMAND_INT_DATA::default()
    })
}

/// How the origin reaches the autopilot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OriginForm {
    /// The SET_GPS_GLOBAL_ORIGIN message (PX4).
    Message,
    /// The COMMAND_INT `MAV_CMD_DO_SET_GLOBAL_ORIGIN` (ArduPilot).
    Command,
}

/// When the origin is announced: when it becomes known, when it moves, and every
/// [`ANNOUNCE_INTERVAL_NS`] of measurement time in between.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OriginAnnouncer {
    target_system: u8,
    form: OriginForm,
    /// The origin last announced and when, ns.
    last: Option<(LocalOrigin, u64)>,
}

impl OriginAnnouncer {
    /// Announces in `form` to the autopilot of system `target_system` (the vehicle's, which rins
    /// shares).
    pub fn new(target_system: u8, form: OriginForm) -> Self {
        Self {
            target_system,
            form,
            last: None,
        }
    }

    /// The announcement due at `nav`'s time for the known origin `origin`, if any.
    pub fn due(&mut self, origin: &LocalOrigin, nav: &NavState) -> Option<MavMessage> {
        let t_ns = nav.header.origin_rx_ns;
        let due = match self.last {
            None => true,
            Some((last, at)) => last != *origin || t_ns.saturating_sub(at) >= ANNOUNCE_INTERVAL_NS,
        };
        if !due {
            return None;
        }
        let m = match self.form {
            OriginForm::Message => MavMessage::SET_GPS_GLOBAL_ORIGIN(set_gps_global_origin(
                origin,
                self.target_system,
                time_usec(nav),
            )?),
            OriginForm::Command => {
                MavMessage::COMMAND_INT(do_set_global_origin(origin, self.target_system)?)
            }
        };
        self.last = Some((*origin, t_ns));
        Some(m)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::integrity_reason;

    fn at(t_s: f64, lat_deg: f64, lon_deg: f64, known: bool) -> NavState {
        let mut nav = NavState {
            latitude_rad: lat_deg.to_radians(),
            longitude_rad: lon_deg.to_radians(),
            altitude_m: 488.25,
            ..NavState::default()
        };
        if !known {
            nav.integrity_reasons |= integrity_reason::POSITION_UNKNOWN;
        }
        nav.header.origin_rx_ns = (t_s * 1e9) as u64;
        nav
    }

    #[test]
    fn the_first_shown_solution_sets_the_origin_and_a_known_position_moves_a_placeholder() {
        let mut o = OriginTracker::default();
        // Not shown: nothing.
        assert_eq!(
            o.observe(&at(1.0, 47.0, 8.0, true), false),
            OriginChange::None
        );
        assert_eq!(o.origin(), None);
        // A placeholder position starts the frame, but is not announced.
        assert_eq!(
            o.observe(&at(2.0, 0.0, 0.0, false), true),
            OriginChange::Set
        );
        assert!(o.origin().is_some() && o.known().is_none());
        assert_eq!(
            o.observe(&at(3.0, 0.0, 0.0, false), true),
            OriginChange::None
        );
        // The first known position moves it, once.
        assert_eq!(
            o.observe(&at(4.0, 47.0, 8.0, true), true),
            OriginChange::Moved
        );
        let known = *o.known().expect("known");
        assert!((known.latitude_rad.to_degrees() - 47.0).abs() < 1e-12);
        assert_eq!(
            o.observe(&at(5.0, 47.1, 8.1, true), true),
            OriginChange::None
        );
        assert_eq!(o.known(), Some(&known));
        // Known from the start: set once, never moved.
        let mut o = OriginTracker::default();
        assert_eq!(
            o.observe(&at(1.0, 47.0, 8.0, true), true),
            OriginChange::Set
        );
        assert_eq!(
            o.observe(&at(2.0, 48.0, 8.0, true), true),
            OriginChange::None
        );
        assert!(o.known().is_some());
    }

    #[test]
    fn the_origin_is_announced_when_known_every_ten_seconds_and_when_it_moves() {
        let origin = LocalOrigin::new(47.397742f64.to_radians(), 8.545594f64.to_radians(), 488.0);
        let mut a = OriginAnnouncer::new(7, OriginForm::Message);
        let Some(MavMessage::SET_GPS_GLOBAL_ORIGIN(first)) =
            a.due(&origin, &at(1.0, 0.0, 0.0, true))
        else {
            panic!("no SET_GPS_GLOBAL_ORIGIN");
        };
        assert_eq!((first.latitude, first.longitude), (473_977_420, 85_455_940));
        assert_eq!((first.altitude, first.target_system), (488_000, 7));
        assert_eq!(first.time_usec, 1_000_000);
        let sent: Vec<f64> = (1..=250)
            .map(|i| 1.0 + f64::from(i) * 0.1)
            .filter(|&t| a.due(&origin, &at(t, 0.0, 0.0, true)).is_some())
            .collect();
        // 1 s, then 11 s and 21 s (±the 0.1 s sample spacing and its rounding).
        assert_eq!(sent.len(), 2, "{sent:?}");
        assert!(
            (sent[0] - 11.0).abs() < 0.15 && (sent[1] - 21.0).abs() < 0.15,
            "{sent:?}"
        );
        // A moved origin goes out at once.
        let moved = LocalOrigin::new(0.5, 0.1, 10.0);
        assert!(a.due(&moved, &at(21.5, 0.0, 0.0, true)).is_some());
        assert!(a.due(&moved, &at(21.6, 0.0, 0.0, true)).is_none());
    }

    #[test]
    fn the_command_form_carries_the_same_origin() {
        let origin = LocalOrigin::new(47.397742f64.to_radians(), 8.545594f64.to_radians(), 488.0);
        let mut a = OriginAnnouncer::new(3, OriginForm::Command);
        let Some(MavMessage::COMMAND_INT(c)) = a.due(&origin, &at(1.0, 0.0, 0.0, true)) else {
            panic!("no COMMAND_INT");
        };
        assert_eq!(c.command, MavCmd::MAV_CMD_DO_SET_GLOBAL_ORIGIN);
        assert_eq!((c.x, c.y, c.z), (473_977_420, 85_455_940, 488.0));
        assert_eq!((c.target_system, c.target_component), (3, 1));
        assert_eq!(c.frame, MavFrame::MAV_FRAME_GLOBAL);
    }

    #[test]
    fn an_origin_the_message_cannot_carry_is_not_announced() {
        let mut a = OriginAnnouncer::new(1, OriginForm::Message);
        let nowhere = LocalOrigin::new(f64::NAN, 0.0, 0.0);
        assert_eq!(a.due(&nowhere, &at(1.0, 0.0, 0.0, true)), None);
        let too_high = LocalOrigin::new(0.1, 0.1, 3e6);
        assert_eq!(set_gps_global_origin(&too_high, 1, 0), None);
        let nav = at(1.0, 0.0, 0.0, true);
        assert!(position_known(&nav));
        assert!(!position_known(&NavState {
            latitude_rad: f64::NAN,
            ..nav
        }));
    }
}
