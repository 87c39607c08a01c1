//! The origin of a local frame that consumers of the navigation stream give positions from: the
//! first shown solution's position, moved once to the first solution whose position is known (with
//! no initial position configured, the navigator's latitude and longitude are placeholders until a
//! GNSS fix, `POSITION_UNKNOWN`). A moved origin is a jump of every local position, so a consumer
//! counts it as a reset of the estimate. MAVLink's local streams and ROS's odometry use it.

use ipc_types::{NavState, integrity_reason};
use rins_earth::local_frame::LocalOrigin;

/// What [`OriginTracker::observe`] did with a solution.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OriginChange {
    /// The origin stays as it was (or there is still none).
    None,
    /// The frame got its first origin.
    Set,
    /// The origin moved: every local position jumps.
    Moved,
}

/// The local frame's origin, and whether it is a known position.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct OriginTracker {
    origin: Option<LocalOrigin>,
    known: bool,
}

/// Whether `nav`'s horizontal position is a position rather than a placeholder.
pub fn position_known(nav: &NavState) -> bool {
    nav.integrity_reasons & integrity_reason::POSITION_UNKNOWN == 0
        && nav.latitude_rad.is_finite()
        && nav.longitude_rad.is_finite()
        && nav.altitude_m.is_finite()
}

impl OriginTracker {
    /// The origin, once a shown solution set it.
    pub fn origin(&self) -> Option<&LocalOrigin> {
        self.origin.as_ref()
    }

    /// The origin when it is a known position: the one to announce.
    pub fn known(&self) -> Option<&LocalOrigin> {
        self.origin.as_ref().filter(|_| self.known)
    }

    /// Takes `nav` (shown or not): the first shown solution sets the origin, the first shown one
    /// with a known position moves a placeholder origin there.
    pub fn observe(&mut self, nav: &NavState, shown: bool) -> OriginChange {
        if !shown || self.known {
            return OriginChange::None;
        }
        let known = position_known(nav);
        let change = match (self.origin, known) {
            (None, _) => OriginChange::Set,
            (Some(_), true) => OriginChange::Moved,
            (Some(_), false) => return OriginChange::None,
        };
        self.origin = Some(LocalOrigin::new(
            nav.latitude_rad,
            nav.longitude_rad,
            nav.altitude_m,
        ));
        self.known = known;
        change
    }
}
