//! The autopilot ODOMETRY is shaped for (`[mavlink] autopilot`): each open autopilot takes the
//! message as an external navigation source only in the frames its receiver accepts, and reads
//! its fields its own way.
//!
//! - `generic`: pose in `MAV_FRAME_LOCAL_NED`, twist in `MAV_FRAME_BODY_FRD`, as the message set
//!   defines them; while there is nothing to show the pose is NaN and the quality −1.
//! - `px4`: the same frames (PX4's receiver maps `LOCAL_NED` to its NED pose frame and
//!   `BODY_FRD` to its body velocity frame); while there is nothing to show the velocity is NaN
//!   too, because PX4 fuses any finite velocity of a message whose quality passes `EKF2_EV_QMIN`,
//!   and a quality of −1 passes the default 0.
//! - `ardupilot`: pose in `MAV_FRAME_LOCAL_FRD`, twist in `MAV_FRAME_BODY_FRD`, the only pair
//!   ArduPilot's receiver takes (it drops every other ODOMETRY). The position is still north,
//!   east, down from rins's origin: an earth-fixed FRD frame whose forward axis points north is the
//!   NED frame, and ArduPilot's MAVLink visual-odometry backend uses the position as NED without
//!   rotating it. ArduPilot does not check the pose for NaN, so nothing is sent while there is
//!   nothing to show: the source goes quiet, which ArduPilot reports as unhealthy.
//!
//! The PX4 and ArduPilot profiles also announce rins's global origin ([`crate::origin`]): both
//! estimators need one to place a local source on the globe.

use crate::dialect::{MavFrame, ODOMETRY_DATA};
use crate::origin::OriginForm;

/// The autopilot the ODOMETRY stream is shaped for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Autopilot {
    /// No particular receiver: the message as the message set defines it.
    Generic,
    /// PX4's EKF2 (external vision).
    Px4,
    /// ArduPilot's EKF3 (external navigation, `VISO_TYPE = 1`).
    Ardupilot,
}

/// The configuration names of [`Autopilot`], in order.
pub const AUTOPILOT_NAMES: [(&str, Autopilot); 3] = [
    ("generic", Autopilot::Generic),
    ("px4", Autopilot::Px4),
    ("ardupilot", Autopilot::Ardupilot),
];

/// What the stream does with ODOMETRY while the solution is not to be shown (not usable, or its
/// integrity invalid).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WhenNothingToShow {
    /// Sent with NaN position and attitude and quality −1.
    NanPose,
    /// Sent with NaN position, attitude and velocity and quality −1.
    NanPoseAndVelocity,
    /// Not sent.
    Withheld,
}

impl Autopilot {
    /// The autopilot named `name` in the configuration.
    pub fn parse(name: &str) -> Result<Self, String> {
        AUTOPILOT_NAMES
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, a)| *a)
            .ok_or_else(|| {
                let names: Vec<&str> = AUTOPILOT_NAMES.iter().map(|(n, _)| *n).collect();
                format!(
                    "mavlink.autopilot = {name:?}: must be one of {}",
                    names.join(", ")
                )
            })
    }

    /// The frame of ODOMETRY's pose and of its twist (velocity and body rates).
    pub fn odometry_frames(self) -> (MavFrame, MavFrame) {
        match self {
            Self::Generic | Self::Px4 => {
                (MavFrame::MAV_FRAME_LOCAL_NED, MavFrame::MAV_FRAME_BODY_FRD)
            }
            Self::Ardupilot => (MavFrame::MAV_FRAME_LOCAL_FRD, MavFrame::MAV_FRAME_BODY_FRD),
        }
    }

    /// What ODOMETRY does while there is nothing to show.
    pub fn when_nothing_to_show(self) -> WhenNothingToShow {
        match self {
            Self::Generic => WhenNothingToShow::NanPose,
            Self::Px4 => WhenNothingToShow::NanPoseAndVelocity,
            Self::Ardupilot => WhenNothingToShow::Withheld,
        }
    }

    /// How the global origin is announced: only to an autopilot that takes it (a generic
    /// receiver may be a ground station, which has no use for it).
    pub fn origin_form(self) -> Option<OriginForm> {
        match self {
            Self::Generic => None,
            Self::Px4 => Some(OriginForm::Message),
            Self::Ardupilot => Some(OriginForm::Command),
        }
    }

    /// `m` (built for a solution that is shown when `shown`) as this autopilot takes it; `None`
    /// when it is not to be sent.
    pub fn shape(self, mut m: ODOMETRY_DATA, shown: bool) -> Option<ODOMETRY_DATA> {
        (m.frame_id, m.child_frame_id) = self.odometry_frames();
        if !shown {
            match self.when_nothing_to_show() {
                WhenNothingToShow::Withheld => return None,
                WhenNothingToShow::NanPoseAndVelocity => {
                    (m.vx, m.vy, m.vz) = (f32::NAN, f32::NAN, f32::NAN);
                    blank_pose(&mut m);
                }
                WhenNothingToShow::NanPose => blank_pose(&mut m),
            }
        }
        Some(m)
    }
}

/// Unknown position and attitude, as the message defines them.
fn blank_pose(m: &mut ODOMETRY_DATA) {
    (m.x, m.y, m.z) = (f32::NAN, f32::NAN, f32::NAN);
    m.q = [f32::NAN; 4];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn built() -> ODOMETRY_DATA {
        ODOMETRY_DATA {
            x: 1.0,
            y: 2.0,
            z: -3.0,
            q: [1.0, 0.0, 0.0, 0.0],
            vx: 4.0,
            vy: 5.0,
            vz: 6.0,
            quality: -1,
            ..ODOMETRY_DATA::default()
        }
    }

    #[test]
    fn each_autopilot_gets_the_frames_its_receiver_takes() {
        let frames = |a: Autopilot| {
            let m = a.shape(built(), true).expect("a shown solution is sent");
            (m.frame_id as u8, m.child_frame_id as u8)
        };
        // MAV_FRAME_LOCAL_NED 1, MAV_FRAME_LOCAL_FRD 20, MAV_FRAME_BODY_FRD 12.
        assert_eq!(frames(Autopilot::Generic), (1, 12));
        assert_eq!(frames(Autopilot::Px4), (1, 12));
        assert_eq!(frames(Autopilot::Ardupilot), (20, 12));
    }

    #[test]
    fn a_solution_not_shown_is_blanked_or_withheld() {
        let generic = Autopilot::Generic.shape(built(), false).expect("sent");
        assert!(generic.x.is_nan() && generic.q[0].is_nan());
        assert_eq!(generic.vx, 4.0, "the generic form keeps the velocity");
        let px4 = Autopilot::Px4.shape(built(), false).expect("sent");
        assert!(px4.x.is_nan() && px4.q[3].is_nan());
        assert!(px4.vx.is_nan() && px4.vy.is_nan() && px4.vz.is_nan());
        assert_eq!(Autopilot::Ardupilot.shape(built(), false), None);
        // Shown: the values are left alone.
        let shown = Autopilot::Ardupilot.shape(built(), true).expect("sent");
        assert_eq!((shown.x, shown.vz), (1.0, 6.0));
    }

    #[test]
    fn names_parse_and_unknown_ones_are_named_in_the_error() {
        assert_eq!(Autopilot::parse("px4"), Ok(Autopilot::Px4));
        assert_eq!(Autopilot::parse("ardupilot"), Ok(Autopilot::Ardupilot));
        assert_eq!(Autopilot::parse("generic"), Ok(Autopilot::Generic));
        let e = Autopilot::parse("ArduPilot").unwrap_err();
        assert_eq!(
            e,
            "mavlink.autopilot = \"ArduPilot\": must be one of generic, px4, ardupilot"
        );
        assert_eq!(Autopilot::Px4.origin_form(), Some(OriginForm::Message));
        assert_eq!(
            Autopilot::Ardupilot.origin_form(),
            Some(OriginForm::Command)
        );
        assert_eq!(Autopilot::Generic.origin_form(), None);
    }
}
