//! The message definitions, field for field in the order of their `.msg` files (the order CDR
//! writes them in).

use serde::de::{Deserialize, Deserializer, SeqAccess, Visitor};
use serde::ser::{Serialize, SerializeTuple, Serializer};

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

impl Time {
    /// The time `ns` nanoseconds after the clock's epoch (seconds saturate at `i32::MAX`).
    pub fn from_ns(ns: u64) -> Self {
        Self {
            sec: i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX),
            nanosec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Header {
    /// When the data was measured.
    pub stamp: Time,
    /// The frame the data is expressed in.
    pub frame_id: String,
}

/// `geometry_msgs/msg/Point`, `geometry_msgs/msg/Vector3` (the same layout).
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl From<[f64; 3]> for Vector3 {
    fn from([x, y, z]: [f64; 3]) -> Self {
        Self { x, y, z }
    }
}

/// `geometry_msgs/msg/Quaternion`: vector part first, scalar last.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w (the scalar part).
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Self {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 1.0,
        }
    }
}

/// A fixed-size `float64[N]` (CDR writes no length; serde's arrays stop at 32 elements).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed<const N: usize>(pub [f64; N]);

impl<const N: usize> Default for Fixed<N> {
    fn default() -> Self {
        Self([0.0; N])
    }
}

impl<const N: usize> Serialize for Fixed<N> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut t = serializer.serialize_tuple(N)?;
        for v in &self.0 {
            t.serialize_element(v)?;
        }
        t.end()
    }
}

impl<'de, const N: usize> Deserialize<'de> for Fixed<N> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct Elements<const N: usize>;
        impl<'de, const N: usize> Visitor<'de> for Elements<N> {
            type Value = Fixed<N>;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{N} float64 values")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Fixed<N>, A::Error> {
                let mut out = [0.0; N];
                for (k, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| serde::de::Error::invalid_length(k, &self))?;
                }
                Ok(Fixed(out))
            }
        }
        deserializer.deserialize_tuple(N, Elements::<N>)
    }
}

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Pose {
    /// Position (a `geometry_msgs/msg/Point`).
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseWithCovariance`: the covariance of (x, y, z, rotation about X, Y, Z),
/// row-major.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// 6 × 6, row-major.
    pub covariance: Fixed<36>,
}

/// `geometry_msgs/msg/Twist`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Twist {
    /// Linear velocity.
    pub linear: Vector3,
    /// Angular velocity.
    pub angular: Vector3,
}

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// 6 × 6, row-major.
    pub covariance: Fixed<36>,
}

/// `nav_msgs/msg/Odometry`: the pose in `header.frame_id`, the twist in `child_frame_id`.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Odometry {
    /// Stamp and the pose's frame.
    pub header: Header,
    /// The twist's frame (the body).
    pub child_frame_id: String,
    /// Pose and covariance.
    pub pose: PoseWithCovariance,
    /// Twist and covariance.
    pub twist: TwistWithCovariance,
}

/// `sensor_msgs/msg/Imu`. A covariance whose first element is −1 says the quantity is not given.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Imu {
    /// Stamp and the body frame.
    pub header: Header,
    /// Orientation.
    pub orientation: Quaternion,
    /// 3 × 3, row-major.
    pub orientation_covariance: Fixed<9>,
    /// Body rate, rad/s.
    pub angular_velocity: Vector3,
    /// 3 × 3, row-major.
    pub angular_velocity_covariance: Fixed<9>,
    /// Specific force, m/s².
    pub linear_acceleration: Vector3,
    /// 3 × 3, row-major.
    pub linear_acceleration_covariance: Fixed<9>,
}

/// `sensor_msgs/msg/NavSatStatus`.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct NavSatStatus {
    /// `STATUS_NO_FIX` −1, `STATUS_FIX` 0, `STATUS_SBAS_FIX` 1, `STATUS_GBAS_FIX` 2.
    pub status: i8,
    /// Bits of `SERVICE_GPS` 1, `SERVICE_GLONASS` 2, `SERVICE_COMPASS` 4, `SERVICE_GALILEO` 8.
    pub service: u16,
}

impl NavSatStatus {
    /// No fix.
    pub const STATUS_NO_FIX: i8 = -1;
    /// Unaugmented fix.
    pub const STATUS_FIX: i8 = 0;
}

/// `sensor_msgs/msg/NavSatFix`: WGS84 latitude and longitude in degrees, altitude in metres.
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct NavSatFix {
    /// Stamp and the frame of the antenna.
    pub header: Header,
    /// Fix status.
    pub status: NavSatStatus,
    /// Degrees, north positive.
    pub latitude: f64,
    /// Degrees, east positive.
    pub longitude: f64,
    /// Metres.
    pub altitude: f64,
    /// East, north, up, m², row-major.
    pub position_covariance: Fixed<9>,
    /// `COVARIANCE_TYPE_UNKNOWN` 0, `_APPROXIMATED` 1, `_DIAGONAL_KNOWN` 2, `_KNOWN` 3.
    pub position_covariance_type: u8,
}

impl NavSatFix {
    /// Only the diagonal of the covariance is known.
    pub const COVARIANCE_TYPE_DIAGONAL_KNOWN: u8 = 2;
}
