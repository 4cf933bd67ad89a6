"""rosgraph_msgs/msg/Clock <-> gz.msgs.Clock (docs/conversions-per-package.md §3.8). Only ``sim`` is
used.

G→R normalises like ``rclcpp::Time``: nanoseconds of 10^9 or more carry into seconds.

Differences from ros_gz_bridge:
- A negative ``sim.sec`` raises ConversionError (the message is dropped) where C++ throws
  an uncaught ``std::runtime_error``.
"""

from __future__ import annotations

from typing import Any

from rosgraph_msgs.msg import Clock

from ros_gz_bridge_py.converters.builtin_interfaces import (
    fill_gz_present_time,
    to_int32,
    to_uint32,
)
from ros_gz_bridge_py.converters.registry import Pair
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.constructors import constructor

GzClock = message_class("gz.msgs.Clock")
_new_clock = constructor(Clock)

_NS_PER_S = 10**9


def clock_to_gz(ros: Any) -> Any:
    gz = GzClock()
    fill_gz_present_time(ros.clock, gz.sim)
    return gz


def clock_to_ros(gz: Any) -> Any:
    sec = to_int32(gz.sim.sec)
    if sec < 0:
        msg = f"gz.msgs.Clock sim.sec={sec} is negative: ROS cannot store a negative time point"
        raise ConversionError(msg)
    total = sec * _NS_PER_S + to_uint32(gz.sim.nsec)
    ros = _new_clock()
    whole, ros.clock.nanosec = divmod(total, _NS_PER_S)
    ros.clock.sec = to_int32(whole)
    return ros


PAIRS = (Pair.of(Clock, "gz.msgs.Clock", clock_to_gz, clock_to_ros),)
