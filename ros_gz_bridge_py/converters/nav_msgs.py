"""nav_msgs/msg/Odometry <-> gz.msgs.Odometry (default) and gz.msgs.OdometryWithCovariance (§3.4).

With gz.msgs.Odometry both ROS covariances are dropped (R→G) and left zero (G→R).
"""

from __future__ import annotations

from typing import Any

from nav_msgs.msg import Odometry

from ros_gz_bridge_py.converters.geometry_msgs import (
    fill_gz_pose,
    fill_gz_pose_with_covariance,
    fill_gz_twist,
    fill_gz_twist_with_covariance,
    fill_ros_pose,
    fill_ros_pose_with_covariance,
    fill_ros_twist,
    fill_ros_twist_with_covariance,
)
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import (
    fill_gz_child_frame_id,
    fill_gz_header,
    fill_ros_header,
    ros_child_frame_id,
)
from ros_gz_bridge_py.msgs import message_class

GzOdometry = message_class("gz.msgs.Odometry")
GzOdometryWithCovariance = message_class("gz.msgs.OdometryWithCovariance")


def _fill_gz_odometry_header(ros: Any, gz: Any) -> None:
    fill_gz_header(ros.header, gz.header)
    fill_gz_child_frame_id(ros.child_frame_id, gz.header)


def _fill_ros_odometry_header(gz: Any, ros: Any) -> None:
    fill_ros_header(gz.header, ros.header)
    ros.child_frame_id = ros_child_frame_id(gz.header)


def odometry_to_gz(ros: Any) -> Any:
    gz = GzOdometry()
    _fill_gz_odometry_header(ros, gz)
    fill_gz_pose(ros.pose.pose, gz.pose)
    fill_gz_twist(ros.twist.twist, gz.twist)
    return gz


def odometry_to_ros(gz: Any) -> Any:
    ros = Odometry()
    _fill_ros_odometry_header(gz, ros)
    fill_ros_pose(gz.pose, ros.pose.pose)
    fill_ros_twist(gz.twist, ros.twist.twist)
    return ros


def odometry_with_covariance_to_gz(ros: Any) -> Any:
    gz = GzOdometryWithCovariance()
    _fill_gz_odometry_header(ros, gz)
    fill_gz_pose_with_covariance(ros.pose, gz.pose_with_covariance)
    fill_gz_twist_with_covariance(ros.twist, gz.twist_with_covariance)
    return gz


def odometry_with_covariance_to_ros(gz: Any) -> Any:
    ros = Odometry()
    _fill_ros_odometry_header(gz, ros)
    fill_ros_pose_with_covariance(gz.pose_with_covariance, ros.pose)
    fill_ros_twist_with_covariance(gz.twist_with_covariance, ros.twist)
    return ros


PAIRS = (
    Pair("nav_msgs/msg/Odometry", "gz.msgs.Odometry", odometry_to_gz, odometry_to_ros, Odometry),
    Pair(
        "nav_msgs/msg/Odometry",
        "gz.msgs.OdometryWithCovariance",
        odometry_with_covariance_to_gz,
        odometry_with_covariance_to_ros,
        Odometry,
    ),
)
