"""ROS 2's own message definitions (nav_msgs, sensor_msgs, diagnostic_msgs and what they use) and a
decoder for each made by mcap-ros2-support's CDR reader (the one Foxglove and the ROS 2 MCAP tools
use); floats are compared as their IEEE 754 bits."""

import struct

from mcap_ros2._dynamic import generate_dynamic

SEP = "\n" + "=" * 80 + "\nMSG: "
COMMON = {
    "std_msgs/Header": "builtin_interfaces/Time stamp\nstring frame_id",
    "builtin_interfaces/Time": "int32 sec\nuint32 nanosec",
    "geometry_msgs/Point": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Vector3": "float64 x\nfloat64 y\nfloat64 z",
    "geometry_msgs/Quaternion": "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1",
    "geometry_msgs/Pose": "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation",
    "geometry_msgs/PoseWithCovariance": "geometry_msgs/Pose pose\nfloat64[36] covariance",
    "geometry_msgs/Twist": "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular",
    "geometry_msgs/TwistWithCovariance": "geometry_msgs/Twist twist\nfloat64[36] covariance",
    "sensor_msgs/NavSatStatus": "int8 status\nuint16 service",
}
TOP = {
    "nav_msgs/Odometry": "std_msgs/Header header\nstring child_frame_id\n"
    "geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist",
    "sensor_msgs/Imu": "std_msgs/Header header\ngeometry_msgs/Quaternion orientation\n"
    "float64[9] orientation_covariance\ngeometry_msgs/Vector3 angular_velocity\n"
    "float64[9] angular_velocity_covariance\ngeometry_msgs/Vector3 linear_acceleration\n"
    "float64[9] linear_acceleration_covariance",
    "sensor_msgs/NavSatFix": "std_msgs/Header header\nsensor_msgs/NavSatStatus status\n"
    "float64 latitude\nfloat64 longitude\nfloat64 altitude\nfloat64[9] position_covariance\n"
    "uint8 position_covariance_type",
    "diagnostic_msgs/DiagnosticArray": "std_msgs/Header header\n"
    "diagnostic_msgs/DiagnosticStatus[] status",
}
COMMON["diagnostic_msgs/DiagnosticStatus"] = (
    "byte level\nstring name\nstring message\nstring hardware_id\ndiagnostic_msgs/KeyValue[] values"
)
COMMON["diagnostic_msgs/KeyValue"] = "string key\nstring value"


def decoder(name):
    """A function from a message's bytes (encapsulation header first) to the message."""
    text = TOP[name] + "".join(SEP + k + "\n" + v for k, v in COMMON.items())
    return generate_dynamic(name, text)[name]


def decode(name, path):
    with open(path, "rb") as f:
        return decoder(name)(f.read())


def bits(values):
    """Each float's IEEE 754 bits as an integer: compared exactly, with no decimal round trip."""
    return [struct.unpack("<Q", struct.pack("<d", x))[0] for x in values]


def vec(v):
    return bits([v.x, v.y, v.z])


def quat(q):
    return bits([q.x, q.y, q.z, q.w])


