"""builtin_interfaces/msg/Time <-> gz.msgs.Time: integer copy with C++ wrap-around.

The rules: docs/conversions.md §1.2.
"""

from __future__ import annotations

import pytest
from builtin_interfaces.msg import Time

from ros_gz_bridge_py.converters.builtin_interfaces import time_to_gz, time_to_ros, to_int32
from ros_gz_bridge_py.msgs import message_class

GzTime = message_class("gz.msgs.Time")


def test_time_round_trips_exactly() -> None:
    gz = time_to_gz(Time(sec=-7, nanosec=123_456_789))
    assert (gz.sec, gz.nsec) == (-7, 123_456_789)
    ros = time_to_ros(gz)
    assert (ros.sec, ros.nanosec) == (-7, 123_456_789)


def test_large_nanosec_is_reinterpreted_as_int32_and_back() -> None:
    gz = time_to_gz(Time(sec=1, nanosec=3_000_000_000))
    assert gz.nsec == 3_000_000_000 - 2**32
    assert time_to_ros(gz).nanosec == 3_000_000_000


def test_gz_to_ros_narrows_without_normalising() -> None:
    ros = time_to_ros(GzTime(sec=2**31 + 5, nsec=-1))
    assert ros.sec == -(2**31) + 5
    assert ros.nanosec == 2**32 - 1


@pytest.mark.parametrize(
    ("value", "expected"), [(0, 0), (2**31 - 1, 2**31 - 1), (2**31, -(2**31)), (-1, -1)]
)
def test_to_int32(value: int, expected: int) -> None:
    assert to_int32(value) == expected
