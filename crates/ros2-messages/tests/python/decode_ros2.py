"""Decodes rins's ROS 2 messages with mcap-ros2-support's CDR reader (the one Foxglove and the
ROS 2 MCAP tools use), from the message definitions of ROS 2's own packages, and prints what it
read as JSON (floats as their bits): python decode_ros2.py ODOMETRY.cdr IMU.cdr NAVSATFIX.cdr"""

import json
import struct
import sys

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
}


def decode(name, path):
    text = TOP[name] + "".join(SEP + k + "\n" + v for k, v in COMMON.items())
    with open(path, "rb") as f:
        return generate_dynamic(name, text)[name](f.read())


def bits(values):
    """Each float's IEEE 754 bits as an integer: compared exactly, with no decimal round trip."""
    return [struct.unpack("<Q", struct.pack("<d", x))[0] for x in values]


def vec(v):
    return bits([v.x, v.y, v.z])


def quat(q):
    return bits([q.x, q.y, q.z, q.w])


odom = decode("nav_msgs/Odometry", sys.argv[1])
imu = decode("sensor_msgs/Imu", sys.argv[2])
fix = decode("sensor_msgs/NavSatFix", sys.argv[3])
print(json.dumps({
    "odometry": {
        "stamp": [odom.header.stamp.sec, odom.header.stamp.nanosec],
        "frame_id": odom.header.frame_id,
        "child_frame_id": odom.child_frame_id,
        "position": vec(odom.pose.pose.position),
        "orientation": quat(odom.pose.pose.orientation),
        "pose_covariance": bits(odom.pose.covariance),
        "linear": vec(odom.twist.twist.linear),
        "angular": vec(odom.twist.twist.angular),
        "twist_covariance": bits(odom.twist.covariance),
    },
    "imu": {
        "frame_id": imu.header.frame_id,
        "orientation": quat(imu.orientation),
        "orientation_covariance": bits(imu.orientation_covariance),
        "angular_velocity": vec(imu.angular_velocity),
        "linear_acceleration": vec(imu.linear_acceleration),
        "linear_acceleration_covariance": bits(imu.linear_acceleration_covariance),
    },
    "navsatfix": {
        "status": [fix.status.status, fix.status.service],
        "lla": bits([fix.latitude, fix.longitude, fix.altitude]),
        "position_covariance": bits(fix.position_covariance),
        "position_covariance_type": fix.position_covariance_type,
    },
}))
