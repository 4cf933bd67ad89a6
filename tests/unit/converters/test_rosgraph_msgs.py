"""rosgraph_msgs/msg/Clock <-> gz.msgs.Clock: only ``sim``, normalised in G→R.

The rules: docs/conversions-per-package.md §3.8.
"""

from __future__ import annotations

import pytest
from rosgraph_msgs.msg import Clock

from ros_gz_bridge_py.converters.rosgraph_msgs import clock_to_gz, clock_to_ros
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class

GzClock = message_class("gz.msgs.Clock")


def test_clock_to_gz_sets_only_sim() -> None:
    ros = Clock()
    gz = clock_to_gz(ros)
    assert gz.HasField("sim")
    assert not gz.HasField("header")
    assert not gz.HasField("system")
    assert not gz.HasField("real")
    ros.clock.sec, ros.clock.nanosec = 12, 345
    gz = clock_to_gz(ros)
    assert (gz.sim.sec, gz.sim.nsec) == (12, 345)
    assert clock_to_ros(gz) == ros


def test_clock_to_ros_carries_nanoseconds_and_ignores_real() -> None:
    gz = GzClock()
    gz.sim.sec, gz.sim.nsec = 3, 1_500_000_000
    gz.real.sec = 99
    ros = clock_to_ros(gz)
    assert (ros.clock.sec, ros.clock.nanosec) == (4, 500_000_000)


def test_negative_sim_time_is_rejected() -> None:
    gz = GzClock()
    gz.sim.sec = -1
    with pytest.raises(ConversionError, match="negative"):
        clock_to_ros(gz)
