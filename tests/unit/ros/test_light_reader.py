"""The light reader of serialized ROS messages gives the converters what rclpy gives them.

For every pair of the registry, a message of the pair's ROS type is filled with distinctive
values (every field different, sequences of several elements, nested messages filled too),
serialized by rclpy, read back by :mod:`ros_gz_bridge_py.ros.light_reader`, and converted to Gazebo
both ways: from rclpy's message and from the light tree. The protobuf messages (or the
conversion errors) must be equal.
"""

from __future__ import annotations

import struct
from typing import Any

import pytest
from rclpy.serialization import deserialize_message, serialize_message

from ros_gz_bridge_py.converters.registry import Pair, default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.ros import light_reader
from tests.ros_values import filled


def _to_gz(pair: Pair, msg: Any) -> tuple[str, Any]:
    try:
        return "ok", pair.to_gz(msg)
    except ConversionError as err:
        return "error", str(err)


PAIRS = list(default_registry().pairs)


@pytest.mark.parametrize("pair", PAIRS, ids=[f"{p.ros_type}-{p.gz_type}" for p in PAIRS])
def test_light_tree_converts_like_rclpy_message(pair: Pair) -> None:
    msg = filled(pair.ros_class)
    cdr = serialize_message(msg)
    tree = light_reader.read(cdr, pair.ros_class)
    assert tree is not None, f"{pair.ros_type} is not readable"
    assert _to_gz(pair, tree) == _to_gz(pair, msg)


def test_at_least_most_pairs_convert_without_error() -> None:
    """The filled messages must exercise real conversions, not only error paths."""
    converted = sum(_to_gz(p, filled(p.ros_class))[0] == "ok" for p in PAIRS)
    assert converted >= len(PAIRS) * 3 // 4


def test_other_encapsulations_are_left_to_rclpy() -> None:
    from geometry_msgs.msg import Twist  # noqa: PLC0415

    cdr = bytearray(serialize_message(filled(Twist)))
    cdr[1] = 0x00  # big endian
    assert light_reader.read(bytes(cdr), Twist) is None


@pytest.mark.parametrize(
    "text",
    [b"hello\x00", b"hello", b"ab\x00cd\x00", b"", b"\x00", b"caf\xc3\xa9"],
    ids=["nul-ended", "no-nul", "nul-inside", "empty", "only-nul", "utf8"],
)
def test_a_string_reads_as_rclpy_reads_it(text: bytes) -> None:
    """A String without its closing NUL lost its last letter ('hello' became 'hell') and one
    of length 0 was refused: rclpy keeps every byte up to the first NUL."""
    from std_msgs.msg import String  # noqa: PLC0415

    cdr = b"\x00\x01\x00\x00" + struct.pack("<I", len(text)) + text
    cdr += b"\x00" * (-len(cdr) % 4)
    tree = light_reader.read(cdr, String)
    assert tree is not None
    assert tree.data == deserialize_message(cdr, String).data


def test_truncated_message_is_a_conversion_error() -> None:
    from nav_msgs.msg import Odometry  # noqa: PLC0415

    cdr = serialize_message(filled(Odometry))
    with pytest.raises(ConversionError, match="Odometry"):
        light_reader.read(cdr[:40], Odometry)


def test_values_land_on_the_right_attributes() -> None:
    from sensor_msgs.msg import JointState  # noqa: PLC0415

    msg = filled(JointState)
    tree = light_reader.read(serialize_message(msg), JointState)
    assert tree is not None
    assert tree.header.frame_id == msg.header.frame_id
    assert (tree.header.stamp.sec, tree.header.stamp.nanosec) == (
        msg.header.stamp.sec,
        msg.header.stamp.nanosec,
    )
    assert tree.name == list(msg.name)
    assert tree.position == tuple(msg.position)
    assert tree.effort == tuple(msg.effort)
