"""trajectory_msgs/msg/JointTrajectory <-> gz.msgs.JointTrajectory (docs/conversions-per-package.md
§3.9).

The point lists are copied whole (no per-element Python loop). ``time_from_start`` is copied
verbatim in R→G and normalised like ``rclcpp::Duration`` in G→R, saturating at the int32 ends.
"""

from __future__ import annotations

from typing import Any

from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from ros_gz_bridge_py.converters._fields import STRINGS, Fill, converters, each, fields, numbers
from ros_gz_bridge_py.converters.builtin_interfaces import fill_gz_present_time, to_int32, to_uint32
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.converters.std_msgs import HEADER

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


def _fill_ros_duration(gz: Any, ros: Any) -> None:
    ros.sec, ros.nanosec = normalize_duration(gz.sec, gz.nsec)


#: ``time_from_start``: verbatim R→G, normalised G→R.
_DURATION = Fill(fill_gz_present_time, _fill_ros_duration)
_POINT = fields(
    ("positions", numbers("d")),
    ("velocities", numbers("d")),
    ("accelerations", numbers("d")),
    ("effort", numbers("d")),
    ("time_from_start", _DURATION),
)
joint_trajectory_to_gz, joint_trajectory_to_ros = converters(
    fields(
        ("header", HEADER),
        ("joint_names", STRINGS),
        ("points", each(_POINT, JointTrajectoryPoint)),
    ),
    JointTrajectory,
    "gz.msgs.JointTrajectory",
)

PAIRS = (
    Pair.of(
        JointTrajectory, "gz.msgs.JointTrajectory", joint_trajectory_to_gz, joint_trajectory_to_ros
    ),
)
