"""A message the native loops cannot copy for Python (no memory) is counted, never handed over
empty (issue 29): an empty payload parses as a valid all-default message, and a /clock of 0
sends simulated time backwards. The allocation is made to fail by the failing-allocation shim
in a subprocess (failed_copy_side.py, failed_copy_ros_side.py), not by a hook in the extension.

Gazebo -> ROS, two copies are made on the way: the loop's (pump.c hand_frames: malloc of the
payload's size, without the GIL) and Python's (take_handed: a bytes object, PyObject_Malloc of
33 bytes more, which is malloc at this size). The pump's ``lost`` count is what
``ChannelPump.dropped`` adds to the channel's drops, which the reader counts in
``messages_dropped`` and the status table in its DROPPED column. ROS -> Gazebo, the same two
(ros_pump.c refuse, ros_loop.c run); the RosPump's ``lost`` goes to the channel's DROPPED.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from tests.unit.native.failing_alloc import environment

pytestmark = pytest.mark.ros

SIDE = Path(__file__).with_name("failed_copy_side.py")
ROS_SIDE = Path(__file__).with_name("failed_copy_ros_side.py")
#: The payload size whose copies fail: no other allocation of the process has their sizes
#: while the loop runs (the shim's count of failures shows it).
SIZE = 100_007
#: The CDR size of the ROS message whose copies fail (a multiple of 4, as DDS pads). rmw's take
#: copies each message into a buffer of its exact size first: that allocation is spared.
ROS_SIZE = 100_008
#: What a bytes object of n bytes asks of PyObject_Malloc beyond n (its header and final NUL).
BYTES_OVERHEAD = 33


@pytest.mark.parametrize(
    "failing", [SIZE, SIZE + BYTES_OVERHEAD], ids=["the-loops-copy", "pythons-copy"]
)
def test_a_payload_that_cannot_be_copied_for_python_is_counted_and_not_handed(
    native: Any, failing: int
) -> None:
    assert native is not None
    result = subprocess.run(
        [sys.executable, str(SIDE), str(failing), str(SIZE)],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-3000:]
    report = json.loads(result.stdout)
    # only the messages a byte longer reach Python, whole: nothing empty, nothing else lost
    assert sorted(report["handed"], key=lambda item: item["kind"]) == [
        {"kind": 0, "sender": "unknown-sender", "size": SIZE + 1},
        {"kind": 1, "sender": "legit-sender", "size": SIZE + 1},
    ], report
    assert report["counts"]["lost"] == 2, report
    assert report["failures"] == 2, report  # the two copies that were meant to fail, only they
    assert report["memory_errors"] == 0, report


@pytest.mark.parametrize(
    ("failing", "spared"),
    [(ROS_SIZE, 1), (ROS_SIZE + BYTES_OVERHEAD, 0)],
    ids=["the-loops-copy", "pythons-copy"],
)
def test_a_ros_message_that_cannot_be_copied_for_python_is_counted_and_not_handed(
    native: Any, failing: int, spared: int
) -> None:
    assert native is not None
    result = subprocess.run(
        [sys.executable, str(ROS_SIDE), str(failing), str(spared), str(ROS_SIZE)],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-3000:]
    report = json.loads(result.stdout)
    assert report["refused"] == [ROS_SIZE + 4], report  # the longer one, whole; nothing empty
    assert (report["counts"]["received"], report["counts"]["lost"]) == (2, 1), report
    assert report["failures"] == 1, report
    assert report["memory_errors"] == 0, report
