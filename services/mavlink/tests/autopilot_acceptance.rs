//! rins's ODOMETRY stream, as each autopilot's receiver takes it. A flight of navigation solutions
//! (alignment, then a free-inertial solution whose horizontal σ grows, a lane switch) is built into
//! ODOMETRY by the crate's own builders for each `[mavlink] autopilot`, framed as MAVLink 2 and
//! read back, and replayed through the conditions each autopilot's source applies, transcribed
//! below as small pure functions. The stream shaped for an autopilot must be taken by it, and a
//! stream shaped for another must not (or not in the frame that autopilot needs).
//!
//! Sources (cited with commits and lines in docs/mavlink.md, "Sources checked"):
//! - ArduPilot `libraries/GCS_MAVLink/GCS_Common.cpp`, `GCS_MAVLINK::handle_odometry` (the 4.7
//!   development line, with `AP_MAVLINK_SET_GPS_GLOBAL_ORIGIN_MESSAGE_ENABLED`): drops any ODOMETRY
//!   whose `frame_id` is not `MAV_FRAME_LOCAL_FRD` or whose `child_frame_id` is not
//!   `MAV_FRAME_BODY_FRD`; `posErr = ∛(c[0]² + c[6]² + c[11]²)` of `pose_covariance` unless `c[0]` is
//!   NaN (then 0); the body velocity rotated to NED by `q`; `quality` passed on.
//! - ArduPilot `libraries/AP_VisualOdom/AP_VisualOdom_MAV.cpp`, `handle_pose_estimate` and
//!   `handle_vision_speed_estimate`: `posErr` constrained to `[VISO_POS_M_NSE, 100]`; the sample is
//!   consumed only when `quality >= VISO_QUAL_MIN` (default 0, −1 consumes everything); no check for
//!   NaN anywhere on the way.
//! - PX4 `src/modules/mavlink/mavlink_receiver.cpp`, `MavlinkReceiver::handle_message_odometry`:
//!   the position is taken only when all three are finite, in the pose frame `LOCAL_NED` → NED,
//!   `LOCAL_ENU` → NED, `LOCAL_FRD` / `LOCAL_FLU` → FRD (others: none); the velocity only when
//!   finite, in `LOCAL_NED` / `LOCAL_ENU` → NED, `LOCAL_FRD` / `LOCAL_FLU` → FRD, `BODY_FRD` (and the
//!   deprecated `BODY_NED`, `BODY_OFFSET_NED`) → body FRD; `estimator_type` `UNKNOWN`, `NAIVE`,
//!   `VISION`, `VIO` publish to `vehicle_visual_odometry` (EKF2's external vision), `MOCAP` to
//!   `vehicle_mocap_odometry`, every other type is refused.
//! - PX4 `src/modules/ekf2/EKF/aid_sources/external_vision/ev_control.cpp`: a sample's quality is
//!   sufficient when `EKF2_EV_QMIN <= 0 || quality >= EKF2_EV_QMIN`.

use ipc_types::{Integrity, NavMode, NavState};
use mavlink::{MavHeader, MavlinkReader, MavlinkVersion};
use rins_mavlink::autopilot::Autopilot;
use rins_mavlink::dialect::{MavEstimatorType, MavFrame, MavMessage, ODOMETRY_DATA};
use rins_mavlink::local_frame::LocalOrigin;
use rins_mavlink::odometry::{ResetCounter, odometry};

/// `[mavlink] odometry_quality_sigma_m` as built in.
const SIGMA_50_M: f64 = 10.0;

// ---------------------------------------------------------------------------------------------
// ArduPilot

/// What ArduPilot's EKF3 is handed from one ODOMETRY.
#[derive(Debug, Clone, Copy, PartialEq)]
struct ArduPilotSample {
    /// The position, m (used as NED).
    position: [f32; 3],
    /// The velocity rotated from the body frame to NED by the message's attitude, m/s.
    velocity_ned: [f32; 3],
    /// The position error ArduPilot derives, m, after its limits.
    pos_err_m: f32,
    /// Whether the sample reaches the EKF (`quality >= VISO_QUAL_MIN`).
    consumed: bool,
}

/// `VISO_POS_M_NSE` default: the floor of the position error, m.
const VISO_POS_M_NSE: f32 = 0.2;

/// ArduPilot's ODOMETRY path (`GCS_MAVLINK::handle_odometry`, then `AP_VisualOdom_MAV`); `None`:
/// dropped before anything is read.
fn ardupilot_receives(m: &ODOMETRY_DATA, viso_qual_min: i8) -> Option<ArduPilotSample> {
    if m.frame_id != MavFrame::MAV_FRAME_LOCAL_FRD
        || m.child_frame_id != MavFrame::MAV_FRAME_BODY_FRD
    {
        return None;
    }
    let c = &m.pose_covariance;
    let pos_err = if c[0].is_nan() {
        0.0
    } else {
        (c[0] * c[0] + c[6] * c[6] + c[11] * c[11]).cbrt()
    };
    Some(ArduPilotSample {
        position: [m.x, m.y, m.z],
        velocity_ned: rotate([m.q[0], m.q[1], m.q[2], m.q[3]], [m.vx, m.vy, m.vz]),
        pos_err_m: pos_err.clamp(VISO_POS_M_NSE, 100.0),
        consumed: m.quality >= viso_qual_min,
    })
}

/// `q ⊗ v ⊗ q*` of a body → NED quaternion [w, x, y, z].
fn rotate(q: [f32; 4], v: [f32; 3]) -> [f32; 3] {
    let [w, x, y, z] = q;
    let r = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    [0, 1, 2].map(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
}

// ---------------------------------------------------------------------------------------------
// PX4

/// The frames of PX4's `vehicle_odometry`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Px4Frame {
    Ned,
    Frd,
    BodyFrd,
}

/// What PX4's receiver publishes for EKF2's external vision from one ODOMETRY.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Px4Sample {
    /// The position and its frame, when finite and in a frame PX4 knows.
    position: Option<(Px4Frame, [f32; 3])>,
    /// The velocity and its frame, likewise.
    velocity: Option<(Px4Frame, [f32; 3])>,
    quality: i8,
}

/// PX4's `handle_message_odometry`; `None`: not published to `vehicle_visual_odometry` (refused,
/// or sent to motion capture).
// PX4 still maps the frames MAVLink has marked superseded.
#[allow(deprecated)]
fn px4_receives(m: &ODOMETRY_DATA) -> Option<Px4Sample> {
    use MavFrame::*;
    match m.estimator_type {
        MavEstimatorType::MAV_ESTIMATOR_TYPE_UNKNOWN
        | MavEstimatorType::MAV_ESTIMATOR_TYPE_NAIVE
        | MavEstimatorType::MAV_ESTIMATOR_TYPE_VISION
        | MavEstimatorType::MAV_ESTIMATOR_TYPE_VIO => {}
        _ => return None,
    }
    let p = [m.x, m.y, m.z];
    let position = if p.iter().all(|v| v.is_finite()) {
        match m.frame_id {
            MAV_FRAME_LOCAL_NED => Some((Px4Frame::Ned, p)),
            MAV_FRAME_LOCAL_ENU => Some((Px4Frame::Ned, [m.y, m.x, -m.z])),
            MAV_FRAME_LOCAL_FRD => Some((Px4Frame::Frd, p)),
            MAV_FRAME_LOCAL_FLU => Some((Px4Frame::Frd, [m.x, -m.y, -m.z])),
            _ => None,
        }
    } else {
        None
    };
    let v = [m.vx, m.vy, m.vz];
    let velocity = if v.iter().all(|x| x.is_finite()) {
        match m.child_frame_id {
            MAV_FRAME_LOCAL_NED => Some((Px4Frame::Ned, v)),
            MAV_FRAME_LOCAL_ENU => Some((Px4Frame::Ned, [m.vy, m.vx, -m.vz])),
            MAV_FRAME_LOCAL_FRD => Some((Px4Frame::Frd, v)),
            MAV_FRAME_LOCAL_FLU => Some((Px4Frame::Frd, [m.vx, -m.vy, -m.vz])),
            MAV_FRAME_BODY_NED | MAV_FRAME_BODY_OFFSET_NED | MAV_FRAME_BODY_FRD => {
                Some((Px4Frame::BodyFrd, v))
            }
            _ => None,
        }
    } else {
        None
    };
    Some(Px4Sample {
        position,
        velocity,
        quality: m.quality,
    })
}

/// EKF2's quality gate (`ev_control.cpp`).
fn px4_quality_sufficient(sample: &Px4Sample, ev_qmin: i8) -> bool {
    ev_qmin <= 0 || sample.quality >= ev_qmin
}

// ---------------------------------------------------------------------------------------------
// The stream

/// A flight: 1 s aligning, then 40 s navigating free-inertial (the horizontal σ growing from
/// 1 m to 41 m), the consumers switching lanes at 20 s; 30 Hz, as ODOMETRY is sent.
fn flight() -> Vec<(NavState, u64)> {
    (0..41 * 30)
        .map(|i| {
            let t = f64::from(i) / 30.0;
            let mut nav = NavState {
                mode: if t < 1.0 {
                    NavMode::Aligning
                } else {
                    NavMode::Navigating
                } as u8,
                integrity: Integrity::Ok as u8,
                quaternion: [0.96592583, 0.0, 0.0, 0.25881905], // 30° heading
                velocity_ned_mps: [8.66, 5.0, -0.5],
                latitude_rad: (47.3977 + t * 1e-5).to_radians(),
                longitude_rad: (8.5456 + t * 1e-5).to_radians(),
                altitude_m: 488.0 + t,
                solution_start_seq: 1,
                ..NavState::default()
            };
            let sigma = 1.0 + (t - 1.0).max(0.0);
            nav.covariance_diag[6] = sigma * sigma / 2.0;
            nav.covariance_diag[7] = sigma * sigma / 2.0;
            nav.covariance_diag[8] = 4.0;
            for c in &mut nav.covariance_diag[..6] {
                *c = 1e-4;
            }
            nav.header.origin_rx_ns = 5_000_000_000 + (t * 1e9) as u64;
            (nav, u64::from(t >= 20.0))
        })
        .collect()
}

/// Whether `nav` is shown (usable, integrity not invalid), as the stream decides.
fn shown(nav: &NavState) -> bool {
    NavMode::from_u8(nav.mode).is_some_and(NavMode::is_usable)
        && nav.integrity != Integrity::Invalid as u8
}

/// The ODOMETRY messages rins sends for `flight` shaped for `autopilot`, each framed as MAVLink 2
/// and read back, with whether its solution was shown.
fn stream(autopilot: Autopilot, flight: &[(NavState, u64)]) -> Vec<(ODOMETRY_DATA, bool)> {
    let origin = flight
        .iter()
        .find(|(n, _)| shown(n))
        .map(|(n, _)| LocalOrigin::new(n.latitude_rad, n.longitude_rad, n.altitude_m))
        .expect("the flight shows a solution");
    let mut resets = ResetCounter::default();
    let mut out = Vec::new();
    for (nav, switches) in flight {
        let counter = resets.observe(nav, *switches);
        let built = odometry(
            nav,
            &origin,
            [0.01, -0.02, 0.03],
            [1e-6; 3],
            counter,
            SIGMA_50_M,
        );
        let Some(m) = autopilot.shape(built, shown(nav)) else {
            continue;
        };
        let header = MavHeader {
            system_id: 1,
            component_id: 197,
            sequence: 0,
        };
        let mut frame = Vec::new();
        mavlink::write_v2_msg(&mut frame, header, &MavMessage::ODOMETRY(m)).expect("encodes");
        let mut reader = MavlinkReader::new(frame.as_slice());
        match reader.read_message::<MavMessage>(MavlinkVersion::V2) {
            Ok((_, MavMessage::ODOMETRY(read))) => out.push((read, shown(nav))),
            other => panic!("ODOMETRY did not read back: {other:?}"),
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// The checks

#[test]
fn ardupilot_takes_the_ardupilot_stream_and_drops_the_others() {
    let flight = flight();
    let sent = stream(Autopilot::Ardupilot, &flight);
    // Nothing is sent while there is nothing to show (ArduPilot would take a NaN pose whenever
    // VISO_QUAL_MIN is −1): the 30 aligning samples are missing, the rest all arrive.
    assert_eq!(sent.len(), flight.len() - 30);
    let mut max_speed_error = 0.0f32;
    for (m, was_shown) in &sent {
        assert!(was_shown);
        let s = ardupilot_receives(m, -1).expect("ArduPilot drops no message of its stream");
        assert!(s.position.iter().all(|v| v.is_finite()), "{s:?}");
        assert!(s.pos_err_m.is_finite() && s.pos_err_m >= VISO_POS_M_NSE);
        // Consumed at the default VISO_QUAL_MIN (0): rins's quality is never 0 or below for a
        // shown solution.
        assert!(ardupilot_receives(m, 0).expect("taken").consumed);
        // The body velocity rotated back by ArduPilot is the solution's NED velocity.
        for (got, want) in s.velocity_ned.iter().zip([8.66f32, 5.0, -0.5]) {
            max_speed_error = max_speed_error.max((got - want).abs());
        }
    }
    // f32 rounding of a 10 m/s velocity through two rotations: well below 1 mm/s.
    assert!(max_speed_error < 1e-3, "{max_speed_error}");
    // With VISO_QUAL_MIN = 50, the samples whose horizontal σ exceeds σ₀ (10 m) are refused: from
    // 10 s of free-inertial navigation on (σ_h = 1 m + 1 m/s).
    let refused_at_50: Vec<bool> = sent
        .iter()
        .map(|(m, _)| !ardupilot_receives(m, 50).expect("taken").consumed)
        .collect();
    let first_refused = refused_at_50.iter().position(|r| *r).expect("some refused");
    let t_first = (first_refused + 30) as f64 / 30.0;
    assert!((t_first - 10.0).abs() < 0.1, "first refused at {t_first} s");
    assert!(refused_at_50[first_refused..].iter().all(|r| *r));
    // The reset counter moved with the lane switch.
    let counters: Vec<u8> = sent.iter().map(|(m, _)| m.reset_counter).collect();
    assert_eq!((counters[0], counters[counters.len() - 1]), (0, 1));

    // The generic and PX4 streams are in LOCAL_NED: ArduPilot drops every one.
    for autopilot in [Autopilot::Generic, Autopilot::Px4] {
        let other = stream(autopilot, &flight);
        assert_eq!(other.len(), flight.len());
        assert!(
            other
                .iter()
                .all(|(m, _)| ardupilot_receives(m, -1).is_none()),
            "{autopilot:?}"
        );
    }
}

#[test]
fn px4_takes_the_px4_stream_in_its_ned_frame_and_never_a_velocity_of_nothing_shown() {
    let flight = flight();
    let sent = stream(Autopilot::Px4, &flight);
    assert_eq!(sent.len(), flight.len());
    let qmin = 50;
    for (m, was_shown) in &sent {
        let s = px4_receives(m).expect("published as external vision");
        if *was_shown {
            assert!(matches!(s.position, Some((Px4Frame::Ned, _))), "{s:?}");
            assert!(matches!(s.velocity, Some((Px4Frame::BodyFrd, _))), "{s:?}");
            // Fused at EKF2_EV_QMIN = 50 while σ_h is within σ₀ (10 m), refused beyond (a
            // margin for the covariance's f32 rounding at the step).
            let sigma_h = (m.pose_covariance[0] + m.pose_covariance[6]).sqrt();
            if !(9.99..=10.01).contains(&sigma_h) {
                assert_eq!(
                    px4_quality_sufficient(&s, qmin),
                    sigma_h < 10.0,
                    "σ_h {sigma_h} quality {}",
                    m.quality
                );
            }
        } else {
            // Nothing to show: neither a position nor a velocity reaches PX4, whatever
            // EKF2_EV_QMIN (the default 0 would let a quality of −1 through).
            assert_eq!((s.position, s.velocity), (None, None), "{s:?}");
            assert_eq!(s.quality, -1);
            assert!(px4_quality_sufficient(&s, 0) && !px4_quality_sufficient(&s, 1));
        }
    }
    // The generic stream hands PX4 the velocity of an aligning solution with quality −1, which
    // EKF2 fuses at the default EKF2_EV_QMIN of 0: the reason for the PX4 profile.
    let generic = stream(Autopilot::Generic, &flight);
    let (aligning, _) = generic
        .iter()
        .find(|(_, s)| !s)
        .expect("an aligning sample");
    let s = px4_receives(aligning).expect("published");
    assert!(s.velocity.is_some() && px4_quality_sufficient(&s, 0));
    // The ArduPilot stream labels the position LOCAL_FRD: PX4 takes it as an FRD frame of
    // unknown heading, not as NED.
    let ardupilot = stream(Autopilot::Ardupilot, &flight);
    for (m, _) in &ardupilot {
        let s = px4_receives(m).expect("published");
        assert!(matches!(s.position, Some((Px4Frame::Frd, _))), "{s:?}");
    }
}

#[test]
fn an_estimator_type_px4_refuses_is_refused() {
    let m = ODOMETRY_DATA {
        estimator_type: MavEstimatorType::MAV_ESTIMATOR_TYPE_GPS_INS,
        ..ODOMETRY_DATA::default()
    };
    assert_eq!(px4_receives(&m), None);
    // rins sends UNKNOWN, which PX4 takes "for legacy support".
    let (m, _) = stream(Autopilot::Px4, &flight())[0].clone();
    assert_eq!(
        m.estimator_type,
        MavEstimatorType::MAV_ESTIMATOR_TYPE_UNKNOWN
    );
}
