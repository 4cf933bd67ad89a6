"""A message the ROS -> Gazebo pump cannot copy for Python (no memory) is counted, never handed
over empty (issue 29), as on the Gazebo -> ROS side (test_pump_failed_copy.py): the loop's copy
(ros_pump_loop.c refuse) and Python's (ros_pump.c take_handed) are made to fail in a subprocess
(failed_copy_ros_side.py) by the failing-allocation shim; the RosPump's ``lost`` goes to the
channel's DROPPED.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.unit.native.failing_alloc import BYTES_OVERHEAD, side

pytestmark = pytest.mark.ros

ROS_SIDE = Path(__file__).with_name("failed_copy_ros_side.py")
#: The CDR size of the ROS message whose copies fail (a multiple of 4: no padding can change
#: it). rmw's take copies each message into a buffer of its exact size first: that allocation
#: is spared.
ROS_SIZE = 100_008


@pytest.mark.parametrize(
    ("failing", "spared"),
    [(ROS_SIZE, 1), (ROS_SIZE + BYTES_OVERHEAD, 0)],
    ids=["the-loops-copy", "pythons-copy"],
)
def test_a_ros_message_that_cannot_be_copied_for_python_is_counted_and_not_handed(
    native: Any, failing: int, spared: int
) -> None:
    assert native is not None
    report = side(ROS_SIDE, failing, spared, ROS_SIZE)
    assert report["refused"] == [ROS_SIZE + 4], report  # the longer one, whole; nothing empty
    assert (report["counts"]["received"], report["counts"]["lost"]) == (2, 1), report
    assert report["failures"] == 1, report
    assert report["memory_errors"] == 0, report
