//! The messages made from rins's payloads. Stamps are given by the caller in the clock ROS nodes
//! use (the system's real time), since rins stamps its samples with the monotonic clock.

use ipc_types::{FusedImu, NavState};
use rins_earth::LocalOrigin;

use crate::frames::{
    attitude_enu_flu, frd_to_flu, ned_covariance_in_flu, ned_to_enu, ned_variances_to_enu,
};
use crate::messages::{
    Fixed, Header, Imu, NavSatFix, NavSatStatus, Odometry, Pose, PoseWithCovariance, Quaternion,
    Time, Twist, TwistWithCovariance, Vector3,
};

/// Where the covariance diagonal of [`NavState::covariance_diag`] holds each block.
const ATTITUDE: usize = 0;
const VELOCITY: usize = 3;
const POSITION: usize = 6;
const GYRO_BIAS: usize = 9;

/// The frame names of REP 105.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameNames<'a> {
    /// The local world frame of the pose (ENU, origin at `origin`), e.g. `map`.
    pub world: &'a str,
    /// The body frame (FLU), e.g. `base_link`.
    pub body: &'a str,
}

fn quaternion([w, x, y, z]: [f64; 4]) -> Quaternion {
    Quaternion { x, y, z, w }
}

fn slice3(v: &[f64]) -> [f64; 3] {
    std::array::from_fn(|k| v.get(k).copied().unwrap_or(f64::NAN))
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|k| a[k] - b[k])
}

/// `nav_msgs/msg/Odometry` of a navigation state: the pose in the ENU frame about `origin`, the
/// twist in the body FLU (the velocity turned into the body; the rate of the fused IMU sample
/// `imu` less the navigator's gyro bias), with the filter's variances on the diagonals (the
/// velocity's turned into the body, so that block is full).
pub fn odometry(
    nav: &NavState,
    imu: &FusedImu,
    origin: &LocalOrigin,
    frames: FrameNames<'_>,
    stamp_ns: u64,
) -> Odometry {
    let p = &nav.covariance_diag;
    let q = nav.quaternion;
    let position = ned_to_enu(origin.ned(nav.latitude_rad, nav.longitude_rad, nav.altitude_m));
    let mut pose_cov = [0.0; 36];
    let (pos_var, rot_var) = (
        ned_variances_to_enu(slice3(&p[POSITION..])),
        ned_variances_to_enu(slice3(&p[ATTITUDE..])),
    );
    for k in 0..3 {
        pose_cov[k * 7] = pos_var[k];
        pose_cov[(k + 3) * 7] = rot_var[k];
    }
    let [w, x, y, z] = q;
    let c_frd_ned =
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(w, x, y, z)).inverse();
    let v_frd: [f64; 3] = (c_frd_ned * nalgebra::Vector3::from(nav.velocity_ned_mps)).into();
    let rate = sub(imu.rate_rps, nav.gyro_bias_rps);
    let mut twist_cov = [0.0; 36];
    let linear = ned_covariance_in_flu(q, slice3(&p[VELOCITY..]));
    let bias_var = slice3(&p[GYRO_BIAS..]);
    for i in 0..3 {
        for j in 0..3 {
            twist_cov[i * 6 + j] = linear[i][j];
        }
        // A sign flip leaves a variance as it is: FRD and FLU share them axis for axis.
        twist_cov[(i + 3) * 7] = imu.rate_var[i] + bias_var[i];
    }
    Odometry {
        header: Header {
            stamp: Time::from_ns(stamp_ns),
            frame_id: frames.world.to_string(),
        },
        child_frame_id: frames.body.to_string(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: position.into(),
                orientation: quaternion(attitude_enu_flu(q)),
            },
            covariance: Fixed(pose_cov),
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: frd_to_flu(v_frd).into(),
                angular: frd_to_flu(rate).into(),
            },
            covariance: Fixed(twist_cov),
        },
    }
}

/// `sensor_msgs/msg/Imu` of a fused sample in the body FLU: the rate and specific force as fused
/// (the specific force reads +g up at rest, as REP 145 has it), their variances on the diagonals,
/// and the orientation of `nav` when there is a usable one (else its covariance is −1: not given).
pub fn imu(fused: &FusedImu, nav: Option<&NavState>, body: &str, stamp_ns: u64) -> Imu {
    let diag = |v: [f64; 3]| {
        let mut m = [0.0; 9];
        for k in 0..3 {
            m[k * 4] = v[k];
        }
        Fixed(m)
    };
    let usable = nav.filter(|n| n.is_shown());
    let (orientation, orientation_covariance) = match usable {
        Some(n) => (
            quaternion(attitude_enu_flu(n.quaternion)),
            diag(ned_variances_to_enu(slice3(&n.covariance_diag[ATTITUDE..]))),
        ),
        None => {
            let mut unknown = [0.0; 9];
            unknown[0] = -1.0;
            (Quaternion::default(), Fixed(unknown))
        }
    };
    Imu {
        header: Header {
            stamp: Time::from_ns(stamp_ns),
            frame_id: body.to_string(),
        },
        orientation,
        orientation_covariance,
        angular_velocity: Vector3::from(frd_to_flu(fused.rate_rps)),
        angular_velocity_covariance: diag(fused.rate_var),
        linear_acceleration: Vector3::from(frd_to_flu(fused.specific_force_mps2)),
        linear_acceleration_covariance: diag(fused.specific_force_var),
    }
}

/// `sensor_msgs/msg/NavSatFix` of a navigation state's position (the navigator's, not a
/// receiver's): a fix while the solution is usable, its position variances (east, north, up) on
/// the diagonal.
pub fn nav_sat_fix(nav: &NavState, frame: &str, stamp_ns: u64) -> NavSatFix {
    let usable = nav.is_shown();
    let var = ned_variances_to_enu(slice3(&nav.covariance_diag[POSITION..]));
    let mut cov = [0.0; 9];
    for k in 0..3 {
        cov[k * 4] = var[k];
    }
    NavSatFix {
        header: Header {
            stamp: Time::from_ns(stamp_ns),
            frame_id: frame.to_string(),
        },
        status: NavSatStatus {
            status: if usable {
                NavSatStatus::STATUS_FIX
            } else {
                NavSatStatus::STATUS_NO_FIX
            },
            service: 0,
        },
        latitude: nav.latitude_rad.to_degrees(),
        longitude: nav.longitude_rad.to_degrees(),
        altitude: nav.altitude_m,
        position_covariance: Fixed(cov),
        position_covariance_type: NavSatFix::COVARIANCE_TYPE_DIAGONAL_KNOWN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ipc_types::NavMode;

    const FRAMES: FrameNames<'static> = FrameNames {
        world: "map",
        body: "base_link",
    };

    /// Level, heading east, 2 m/s north and 1 m/s down, 30 m north of the origin; the fused
    /// sample at rest but turning left at 0.1 rad/s (FRD z is down: a negative rate).
    fn state() -> (NavState, FusedImu, LocalOrigin) {
        let origin = LocalOrigin::new(0.8, 0.15, 100.0);
        let [lat, lon, alt] = origin.geodetic([30.0, 0.0, 0.0]);
        let half = std::f64::consts::FRAC_PI_4;
        let mut nav = NavState {
            mode: NavMode::Navigating as u8,
            quaternion: [half.cos(), 0.0, 0.0, half.sin()],
            velocity_ned_mps: [2.0, 0.0, 1.0],
            latitude_rad: lat,
            longitude_rad: lon,
            altitude_m: alt,
            ..NavState::default()
        };
        nav.covariance_diag[POSITION] = 4.0; // north
        nav.covariance_diag[POSITION + 1] = 1.0; // east
        nav.gyro_bias_rps = [0.0, 0.0, 0.01];
        let imu = FusedImu {
            rate_rps: [0.0, 0.0, -0.09],
            specific_force_mps2: [0.0, 0.0, -9.81],
            rate_var: [1e-4; 3],
            ..FusedImu::default()
        };
        (nav, imu, origin)
    }

    #[test]
    fn an_odometry_reads_in_ros_frames() {
        let (nav, imu, origin) = state();
        let o = odometry(&nav, &imu, &origin, FRAMES, 1_500_000_000);
        assert_eq!(
            o.header.stamp,
            Time {
                sec: 1,
                nanosec: 500_000_000
            }
        );
        assert_eq!(
            (o.header.frame_id.as_str(), o.child_frame_id.as_str()),
            ("map", "base_link")
        );
        let p = o.pose.pose.position;
        assert!(
            p.x.abs() < 1e-6 && (p.y - 30.0).abs() < 1e-6 && p.z.abs() < 1e-6,
            "{p:?}"
        );
        // Heading east is a yaw of 0 in ENU: the identity.
        let q = o.pose.pose.orientation;
        assert!((q.w.abs() - 1.0).abs() < 1e-12, "{q:?}");
        // North is to the left of a body facing east, down is down.
        let v = o.twist.twist.linear;
        assert!(
            v.x.abs() < 1e-12 && (v.y - 2.0).abs() < 1e-12 && (v.z + 1.0).abs() < 1e-12,
            "{v:?}"
        );
        // Turning left is a positive yaw rate about the body's up axis, less the bias.
        assert!((o.twist.twist.angular.z - 0.1).abs() < 1e-12);
        // North variance on y, east on x.
        let c = o.pose.covariance.0;
        assert_eq!((c[0], c[7]), (1.0, 4.0));
    }

    #[test]
    fn an_imu_at_rest_reads_plus_g_up_and_says_when_it_has_no_orientation() {
        let (nav, fused, _) = state();
        let m = imu(&fused, Some(&nav), "base_link", 0);
        assert!((m.linear_acceleration.z - 9.81).abs() < 1e-12);
        assert!(m.orientation_covariance.0[0] >= 0.0);
        let aligning = NavState {
            mode: NavMode::Aligning as u8,
            ..nav
        };
        let m = imu(&fused, Some(&aligning), "base_link", 0);
        assert_eq!(m.orientation_covariance.0[0], -1.0);
        assert_eq!(
            imu(&fused, None, "base_link", 0).orientation_covariance.0[0],
            -1.0
        );
    }

    #[test]
    fn a_fix_in_degrees_with_its_variances_east_north_up() {
        let (nav, _, _) = state();
        let f = nav_sat_fix(&nav, "gps", 0);
        assert!((f.latitude - nav.latitude_rad.to_degrees()).abs() < 1e-12);
        assert_eq!(f.status.status, NavSatStatus::STATUS_FIX);
        assert_eq!(
            (f.position_covariance.0[0], f.position_covariance.0[4]),
            (1.0, 4.0)
        );
        let invalid = NavState {
            mode: NavMode::Invalid as u8,
            ..nav
        };
        assert_eq!(
            nav_sat_fix(&invalid, "gps", 0).status.status,
            NavSatStatus::STATUS_NO_FIX
        );
        // A navigating solution whose integrity is invalid is no fix either, and orients no IMU
        // sample: what MAVLink withholds, ROS is not told.
        let untrusted = NavState {
            integrity: ipc_types::Integrity::Invalid as u8,
            ..nav
        };
        assert_eq!(
            nav_sat_fix(&untrusted, "gps", 0).status.status,
            NavSatStatus::STATUS_NO_FIX
        );
        let (_, fused, _) = state();
        assert_eq!(
            imu(&fused, Some(&untrusted), "base_link", 0)
                .orientation_covariance
                .0[0],
            -1.0
        );
    }
}
