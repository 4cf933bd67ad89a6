"""The header rewrite of a Gazebo -> ROS channel (``frame_id``,
``override_timestamps_with_wall_time``) on the native path: the bytes of the Python path, which
converts and then rewrites the top-level header (``core/gz_to_ros.py``), for every pair with
one; messages without a top-level header are written unchanged (docs/native.md §3)."""

from __future__ import annotations

import struct
import time
from typing import Any

import pytest

from ros_gz_bridge_py.converters.registry import Pair, default_registry
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native.program import compile_to_ros
from ros_gz_bridge_py.native.words import NotExpressibleError
from ros_gz_bridge_py.ros.cdr_writer import writer_for
from tools.native_fuzz_programs import distinctive

OK = 0
FRAME = "override::frame/x"
#: Where a top-level header's stamp is in the CDR: the first field, after the encapsulation.
STAMP = struct.Struct("<iI")


def _with_header() -> list[Pair]:
    found = []
    for pair in default_registry().pairs:
        if pair.ros_class.get_fields_and_field_types().get("header") != "std_msgs/Header":
            continue
        try:
            compile_to_ros(pair)
        except NotExpressibleError:
            continue
        found.append(pair)
    return found


PAIRS = _with_header()


def _program(native: Any, pair: Pair, *, frame_id: str = "", wall_stamp: bool = False) -> Any:
    compiled = compile_to_ros(pair, frame_id=frame_id, wall_stamp=wall_stamp)
    return native.Program(compiled.schema, compiled.ops)


def _python(
    pair: Pair, payload: bytes, *, frame_id: str = "", stamp: tuple[int, int] | None = None
) -> bytes:
    ros = pair.to_ros(message_class(pair.gz_type).FromString(payload))
    if frame_id:
        ros.header.frame_id = frame_id
    if stamp is not None:
        ros.header.stamp.sec, ros.header.stamp.nanosec = stamp
    writer = writer_for(pair.ros_class)
    assert writer is not None
    return writer(ros)


def test_pairs_with_a_header_compile() -> None:
    names = {pair.ros_type for pair in PAIRS}
    assert {"nav_msgs/msg/Odometry", "sensor_msgs/msg/Imu", "sensor_msgs/msg/JointState"} <= names


@pytest.mark.parametrize("pair", PAIRS, ids=[f"{p.ros_type}-{p.gz_type}" for p in PAIRS])
def test_the_frame_id_is_rewritten_as_python_does(native: Any, pair: Pair) -> None:
    payload = distinctive(pair.gz_type).SerializeToString()
    status, cdr = _program(native, pair, frame_id=FRAME).to_cdr(payload)
    assert status == OK
    assert cdr == _python(pair, payload, frame_id=FRAME)


@pytest.mark.parametrize("pair", PAIRS, ids=[f"{p.ros_type}-{p.gz_type}" for p in PAIRS])
def test_the_stamp_is_the_wall_clock_of_the_write(native: Any, pair: Pair) -> None:
    payload = distinctive(pair.gz_type).SerializeToString()
    before = time.time_ns()
    status, cdr = _program(native, pair, frame_id=FRAME, wall_stamp=True).to_cdr(payload)
    after = time.time_ns()
    assert status == OK
    assert cdr is not None
    sec, nanosec = STAMP.unpack_from(cdr, 4)
    assert before <= sec * 10**9 + nanosec <= after
    assert cdr == _python(pair, payload, frame_id=FRAME, stamp=(sec, nanosec))


def test_a_message_without_a_top_level_header_is_not_rewritten(native: Any) -> None:
    pair = default_registry().get("geometry_msgs/msg/Twist", "gz.msgs.Twist")
    payload = distinctive(pair.gz_type).SerializeToString()
    plain = _program(native, pair).to_cdr(payload)
    assert _program(native, pair, frame_id=FRAME, wall_stamp=True).to_cdr(payload) == plain
