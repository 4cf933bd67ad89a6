"""Payloads built to cost: the native transcoder's work stays linear in the payload, and an
output far larger than its payload is refused on both paths (docs/native.md §4).

The work is counted, not timed: ``Program.steps`` is the number of protobuf fields the last
``to_cdr`` read. Validating a payload reads each of its fields once and indexing each message
the ops read reads them once more, so fields the program never reads (unknown ones, here) cost
two steps each, however many ops the program has. Before the index, every op rescanned its
message: an Odometry followed by 768 KiB of small unknown fields took 60-72 ms natively.
"""

from __future__ import annotations

import struct
from typing import Any

import pytest
from geometry_msgs.msg import Pose, TransformStamped

from ros_gz_bridge_py.converters._limits import (
    MAX_OUTPUT,
    OUTPUT_FLOOR,
    OUTPUT_RATIO,
    least_item_bytes,
)
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.msgs import message_class
from tests.unit.native import gz_payloads as gzp
from tests.unit.native.test_transcode import FALLBACK, IDS, OK, PAIRS, TOO_LARGE, Transcoder
from tools.native_fuzz_programs import distinctive

#: A small unknown field: a two-byte tag (field 2000) and a one-byte varint.
JUNK_FIELD = gzp.tag(2000, gzp.VARINT) + gzp.varint(1)
#: About 768 KiB of them.
JUNK_COUNT = 768 * 1024 // len(JUNK_FIELD)
JUNK = JUNK_FIELD * JUNK_COUNT


def _pair(ros_type: str, gz_type: str) -> Transcoder:
    for pair, compiled in PAIRS:
        if (pair.ros_type, pair.gz_type) == (ros_type, gz_type):
            return Transcoder(pair, compiled)
    msg = f"{ros_type} <- {gz_type} has no native program"
    raise AssertionError(msg)


def _written_alike(transcoder: Transcoder, payload: bytes) -> int:
    """Asserts that both paths write ``payload`` alike (without printing it: it is large);
    returns the fields the native path read."""
    status, cdr = transcoder.program.to_cdr(payload)
    steps = int(transcoder.program.steps)
    outcome, reference = transcoder.python(payload)
    where = f"{transcoder.pair.ros_type}: native {status}, Python {outcome}"
    assert status == outcome == OK, where
    assert cdr == reference, where
    return steps


def _extra_steps(transcoder: Transcoder, payload: bytes, hostile: bytes) -> int:
    """The fields the transcoder read for ``hostile`` beyond those it read for ``payload``."""
    return _written_alike(transcoder, hostile) - _written_alike(transcoder, payload)


def test_odometry_after_unknown_fields_costs_two_steps_a_field() -> None:
    odometry = _pair("nav_msgs/msg/Odometry", "gz.msgs.Odometry")
    payload = distinctive("gz.msgs.Odometry").SerializeToString()
    for hostile in (payload + JUNK, JUNK + payload):
        assert _extra_steps(odometry, payload, hostile) <= 2 * JUNK_COUNT


def test_unknown_fields_inside_submessages_cost_two_steps_a_field() -> None:
    """Junk in the header, the pose and its position: each message is indexed once however
    many ops read it (Odometry reads the position three times, the pose seven)."""
    odometry = _pair("nav_msgs/msg/Odometry", "gz.msgs.Odometry")
    msg = distinctive("gz.msgs.Odometry")
    payload = msg.SerializeToString()
    pose = msg.pose
    position = pose.position.SerializeToString() + JUNK
    pose.ClearField("position")
    pose_bytes = pose.SerializeToString() + gzp.length_delimited(4, position) + JUNK
    header = msg.header.SerializeToString() + JUNK
    msg.ClearField("header")
    msg.ClearField("pose")
    rest = msg.SerializeToString()
    hostile = gzp.length_delimited(1, header) + rest + gzp.length_delimited(2, pose_bytes)
    assert _extra_steps(odometry, payload, hostile) <= 2 * 3 * JUNK_COUNT


@pytest.mark.parametrize(("pair", "compiled"), PAIRS, ids=IDS)
def test_unknown_fields_around_any_message_cost_two_steps_a_field(pair: Any, compiled: Any) -> None:
    transcoder = Transcoder(pair, compiled)
    payload = distinctive(pair.gz_type).SerializeToString()
    junk = JUNK_FIELD * 4096
    assert _extra_steps(transcoder, payload, junk + payload + junk) <= 2 * 2 * 4096


def _empty_poses(count: int) -> bytes:
    return gzp.length_delimited(2, b"") * count  # Pose_V.pose


#: The ROS item of each list a Pose_V becomes.
ITEMS = {"tf2_msgs/msg/TFMessage": TransformStamped, "geometry_msgs/msg/PoseArray": Pose}


@pytest.mark.parametrize(
    ("ros_type", "count"),
    [("tf2_msgs/msg/TFMessage", 200_000), ("geometry_msgs/msg/PoseArray", 2_500_000)],
)
def test_empty_poses_past_the_bound_are_refused_natively(ros_type: str, count: int) -> None:
    """400 KB of empty poses would make 14 MB of transforms, 5 MB would make 140 MB of poses:
    the native path refuses them itself (RGB_TOO_LARGE) with the figures of its refusal, and
    only where the Python path refuses them too (its least item is never smaller), so no
    payload is handed to Python to be parsed item by item (4 M poses took 300 MB there)."""
    transcoder = _pair(ros_type, "gz.msgs.Pose_V")
    payload = _empty_poses(count)
    status, figures = transcoder.program.to_cdr(payload)
    assert status == TOO_LARGE
    assert isinstance(figures, tuple)
    items, least = figures
    assert items == count
    assert 0 < least <= least_item_bytes(ITEMS[ros_type])
    gz = message_class("gz.msgs.Pose_V").FromString(payload)
    with pytest.raises(ConversionError, match=rf"{count} \w+ items .* over the limit"):
        transcoder.pair.to_ros(gz)


def test_empty_poses_near_the_bound_are_left_to_python() -> None:
    """Between the bound and the most Python's bound allows (its size of a message can be up to
    twice the payload's), the native path is not sure: it leaves the payload to Python, which
    refuses this one."""
    transcoder = _pair("geometry_msgs/msg/PoseArray", "gz.msgs.Pose_V")
    payload = _empty_poses(200_000)  # 400 KB that would become 11 MB
    assert transcoder.program.to_cdr(payload) == (FALLBACK, None)
    gz = message_class("gz.msgs.Pose_V").FromString(payload)
    with pytest.raises(ConversionError, match=r"200000 Pose items .* over the limit"):
        transcoder.pair.to_ros(gz)


@pytest.mark.parametrize(
    "ros_type", ["tf2_msgs/msg/TFMessage", "geometry_msgs/msg/PoseArray"]
)  # fmt: skip
def test_large_messages_within_the_bound_pass(ros_type: str) -> None:
    """Empty poses up to the floor, and many distinctive poses, are written alike."""
    transcoder = _pair(ros_type, "gz.msgs.Pose_V")
    assert transcoder.check(_empty_poses(400), well_formed=True) == OK
    pose = distinctive("gz.msgs.Pose_V").pose[0].SerializeToString()
    assert transcoder.check(gzp.length_delimited(2, pose) * 20_000, well_formed=True) == OK


def test_no_output_exceeds_the_cap_on_either_path() -> None:
    """Poses that each carry one coordinate are within the ratio (56 bytes written for 13 read),
    but 2.4 M of them (31 MB) would make a PoseArray of 134 MB: past MAX_OUTPUT both paths
    refuse it (before the cap, both wrote it)."""
    transcoder = _pair("geometry_msgs/msg/PoseArray", "gz.msgs.Pose_V")
    x = gzp.tag(2, 1) + struct.pack("<d", 1.5)  # Vector3d.x, a double
    pose = gzp.length_delimited(4, x)  # Pose.position
    count = MAX_OUTPUT // 56 + 1000
    payload = gzp.length_delimited(2, pose) * count  # Pose_V.pose
    assert OUTPUT_FLOOR + OUTPUT_RATIO * len(payload) > 56 * count  # within the ratio
    status, figures = transcoder.program.to_cdr(payload)
    assert (status, figures) == (TOO_LARGE, (count, 56))
    gz = message_class("gz.msgs.Pose_V").FromString(payload)
    with pytest.raises(ConversionError, match=rf"{count} Pose items .* at most {MAX_OUTPUT}"):
        transcoder.pair.to_ros(gz)


def test_every_distinctive_message_is_within_the_bound() -> None:
    """The bound's headroom on the test values of every pair that compiles: their output
    beyond the floor is well under the ratio."""
    for pair, compiled in PAIRS:
        transcoder = Transcoder(pair, compiled)
        payload = distinctive(pair.gz_type).SerializeToString()
        status, cdr = transcoder.program.to_cdr(payload)
        assert status == OK
        assert cdr is not None
        assert len(cdr) <= OUTPUT_FLOOR // 4 + OUTPUT_RATIO // 4 * len(payload), pair


def test_a_large_output_does_not_keep_its_buffer() -> None:
    transcoder = _pair("tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V")
    pose = distinctive("gz.msgs.Pose_V").pose[0].SerializeToString()
    status, cdr = transcoder.program.to_cdr(gzp.length_delimited(2, pose) * 20_000)
    assert status == OK
    assert cdr is not None
    assert len(cdr) > 2 * 2**20
    assert transcoder.program.kept_bytes <= 2**20
    assert transcoder.program.to_cdr(gzp.length_delimited(2, pose))[0] == OK
    assert 0 < transcoder.program.kept_bytes <= 2**20
