"""trajectory_msgs/msg/JointTrajectory <-> gz.msgs.JointTrajectory (conversions.md §3.9).

The point lists are copied whole (no per-element Python loop). ``time_from_start`` is copied
verbatim in R→G and normalised like ``rclcpp::Duration`` in G→R, saturating at the int32 ends.
"""

from __future__ import annotations

from array import array
from typing import Any

from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from ros_gz_bridge_py.converters.builtin_interfaces import to_int32, to_uint32
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import fill_gz_header, fill_ros_header
from ros_gz_bridge_py.msgs import message_class

_GzJointTrajectory = message_class("gz.msgs.JointTrajectory")

_NS_PER_S = 10**9
_INT32_MAX = (1 << 31) - 1
_INT32_MIN = -(1 << 31)
_UINT32_MAX = (1 << 32) - 1


def normalize_duration(sec: int, nsec: int) -> tuple[int, int]:
    """gz Duration (int64 sec, int32 nsec) -> ROS (sec, nanosec) as ``rclcpp::Duration`` does.

    Both parts are narrowed first (int32 wrap, uint32 wrap), then carried through one int64
    nanosecond total; results beyond the int32 seconds range saturate.
    """
    total = to_int32(sec) * _NS_PER_S + to_uint32(nsec)
    # C std::div: quotient truncated toward zero, remainder with the sign of total.
    quotient = abs(total) // _NS_PER_S * (1 if total >= 0 else -1)
    remainder = total - quotient * _NS_PER_S
    if remainder >= 0:
        if quotient > _INT32_MAX:
            return _INT32_MAX, _UINT32_MAX
        return quotient, remainder
    if quotient <= _INT32_MIN:
        return _INT32_MIN, 0
    return quotient - 1, _NS_PER_S + remainder


def joint_trajectory_to_gz(ros: Any) -> Any:
    gz = _GzJointTrajectory()
    fill_gz_header(ros.header, gz.header)
    gz.joint_names.extend(ros.joint_names)
    for ros_point in ros.points:
        gz_point = gz.points.add()
        gz_point.positions.extend(ros_point.positions)
        gz_point.velocities.extend(ros_point.velocities)
        gz_point.accelerations.extend(ros_point.accelerations)
        gz_point.effort.extend(ros_point.effort)
        duration = gz_point.time_from_start
        duration.SetInParent()
        duration.sec = ros_point.time_from_start.sec
        duration.nsec = to_int32(ros_point.time_from_start.nanosec)
    return gz


def joint_trajectory_to_ros(gz: Any) -> Any:
    ros = JointTrajectory()
    fill_ros_header(gz.header, ros.header)
    ros.joint_names = list(gz.joint_names)
    points = []
    for gz_point in gz.points:
        ros_point = JointTrajectoryPoint()
        ros_point.positions = array("d", gz_point.positions)
        ros_point.velocities = array("d", gz_point.velocities)
        ros_point.accelerations = array("d", gz_point.accelerations)
        ros_point.effort = array("d", gz_point.effort)
        sec, nanosec = normalize_duration(
            gz_point.time_from_start.sec, gz_point.time_from_start.nsec
        )
        ros_point.time_from_start.sec = sec
        ros_point.time_from_start.nanosec = nanosec
        points.append(ros_point)
    ros.points = points
    return ros


PAIRS = (
    Pair(
        "trajectory_msgs/msg/JointTrajectory",
        "gz.msgs.JointTrajectory",
        joint_trajectory_to_gz,
        joint_trajectory_to_ros,
        JointTrajectory,
    ),
)
