"""Decodes rins's ROS 2 messages with mcap-ros2-support's CDR reader (the one Foxglove and the
ROS 2 MCAP tools use), from the message definitions of ROS 2's own packages, and prints what it
read as JSON (floats as their bits): python decode_ros2.py ODOMETRY.cdr IMU.cdr NAVSATFIX.cdr"""

import json
import sys

from ros2_definitions import bits, decode, quat, vec

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
