"""A message the Gazebo -> ROS pump cannot copy for Python (no memory) is counted, never handed
over empty (issue 29): an empty payload parses as a valid all-default message, and a /clock of
0 sends simulated time backwards. The allocation is made to fail by the failing-allocation shim
in a subprocess (failed_copy_side.py), not by a hook in the extension.

Two copies are made on the way: the loop's (pump_loop.c hand_frames: malloc of the payload's
size, without the GIL) and Python's (pump.c take_handed: a bytes object, PyObject_Malloc of 33
bytes more, which is malloc at this size). The pump's ``lost`` count is what
``ChannelPump.dropped`` adds to the channel's drops, which the reader counts in
``messages_dropped`` and the status table in its DROPPED column. The other allocation on a
payload's way, the transcoder's output buffer, falls back instead: the payload goes to the
Python path whole. ROS -> Gazebo: test_ros_pump_failed_copy.py.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from tests.unit.native.failing_alloc import BYTES_OVERHEAD, side

pytestmark = pytest.mark.ros

SIDE = Path(__file__).with_name("failed_copy_side.py")
#: The payload size whose copies fail: no other allocation of the process has their sizes
#: while the loop runs (the shim's count of failures shows it).
SIZE = 100_007
#: A String payload whose CDR output needs the transcoder's buffer grown to GROWN_OUTPUT bytes.
GROW_SIZE, GROWN_OUTPUT = 150_004, 262_144
#: The transcoder's statuses (transcode.h).
UNDECODABLE, FALLBACK = 1, 3


@pytest.mark.parametrize(
    "failing", [SIZE, SIZE + BYTES_OVERHEAD], ids=["the-loops-copy", "pythons-copy"]
)
def test_a_payload_that_cannot_be_copied_for_python_is_counted_and_not_handed(
    native: Any, failing: int
) -> None:
    assert native is not None
    report = side(SIDE, "copy", failing, SIZE)
    # only the messages a byte longer reach Python, whole: nothing empty, nothing else lost
    assert sorted(report["handed"], key=lambda item: item["kind"]) == [
        {"kind": 0, "sender": "unknown-sender", "size": SIZE + 1, "status": None},
        {"kind": 1, "sender": "legit-sender", "size": SIZE + 1, "status": UNDECODABLE},
    ], report
    assert report["counts"]["lost"] == 2, report
    assert report["failures"] == 2, report  # the two copies that were meant to fail, only they
    assert report["memory_errors"] == 0, report


def test_an_output_buffer_that_cannot_grow_leaves_the_message_to_python(native: Any) -> None:
    """The transcoder's output buffer (wire.h rgb_grow: doubled from 256 bytes, to 262144 for
    a String of 150004 bytes) cannot grow: the program says FALLBACK and the payload goes to
    the Python path whole, which converts it; nothing is lost (without the failure the loop
    publishes it itself)."""
    assert native is not None
    report = side(SIDE, "grow", GROWN_OUTPUT, GROW_SIZE)
    assert report["handed"] == [
        {"kind": 1, "sender": "legit-sender", "size": GROW_SIZE, "status": FALLBACK}
    ], report
    assert (report["counts"]["published"], report["counts"]["lost"]) == (0, 0), report
    assert report["failures"] == 1, report
