"""builtin_interfaces/msg/Time <-> gz.msgs.Time (docs/conversions.md §1.2).

Times are copied field by field with C++ integer semantics and no normalisation: seconds
narrow to int32 and nanoseconds are reinterpreted between uint32 and int32.
"""

from __future__ import annotations

from typing import Any

from builtin_interfaces.msg import Time

from ros_gz_bridge_py.converters._fields import Fill, converters
from ros_gz_bridge_py.converters.registry import Pair

_U32 = 1 << 32
_I32_MAX = (1 << 31) - 1


def to_int32(value: int) -> int:
    """Two's-complement narrowing to int32, as a C++ static_cast does."""
    value &= _U32 - 1
    return value - _U32 if value > _I32_MAX else value


def to_uint32(value: int) -> int:
    """Two's-complement reinterpretation as uint32 (a negative value wraps to 2^32+v)."""
    return value & (_U32 - 1)


def fill_gz_time(ros: Any, gz: Any) -> None:
    """Write ROS Time (or Duration) ``ros`` into gz Time ``gz``."""
    gz.sec = ros.sec
    gz.nsec = to_int32(ros.nanosec)


def fill_ros_time(gz: Any, ros: Any) -> None:
    """Write gz Time ``gz`` into ROS Time (or Duration) ``ros``."""
    ros.sec = to_int32(gz.sec)
    ros.nanosec = to_uint32(gz.nsec)


def fill_gz_present_time(ros: Any, gz: Any) -> None:
    """:func:`fill_gz_time` into a gz Time that is serialized even when it is zero."""
    gz.SetInParent()
    fill_gz_time(ros, gz)


TIME = Fill(fill_gz_time, fill_ros_time)
#: A ROS Time or Duration <-> a gz Time that is always present on the wire.
PRESENT_TIME = Fill(fill_gz_present_time, fill_ros_time)

time_to_gz, time_to_ros = converters(TIME, Time, "gz.msgs.Time")

PAIRS = (Pair.of(Time, "gz.msgs.Time", time_to_gz, time_to_ros),)
