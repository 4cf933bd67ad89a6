"""The compiled CDR writer writes what rclpy writes, and refuses what it cannot write alike.

For every pair of the registry: a message of the pair's ROS type filled with distinctive
values (tests/ros_values.py), and the message the pair's converter makes from its Gazebo
conversion (what a Gazebo -> ROS channel publishes), are serialized by rclpy and by the
writer. rclpy leaves alignment padding uninitialised, and its buffer is as long as Fast DDS's
size estimate, which counts alignment an empty sequence of 8-byte numbers does not get on the
wire (its trailing bytes are garbage). Every byte the writer writes must be rclpy's but for
padding, and both must read back as the same message.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from rclpy.serialization import deserialize_message, serialize_message

from ros_gz_bridge_py.converters.registry import Pair, default_registry
from ros_gz_bridge_py.errors import ConversionError
from ros_gz_bridge_py.ros import cdr_writer
from tests.ros_values import filled

PAIRS = list(default_registry().pairs)
ROS_CLASSES = sorted(
    {pair.ros_class for pair in PAIRS}, key=lambda cls: cls.__module__ + cls.__name__
)


def assert_same_cdr(msg: Any) -> None:
    """The writer's bytes are rclpy's but for padding, and read back as the same message."""
    writer = cdr_writer.writer_for(type(msg))
    assert writer is not None, f"{type(msg).__name__} has no writer"
    ours, theirs = writer(msg), serialize_message(msg)
    assert len(ours) <= len(theirs), (len(ours), len(theirs))
    differing = [i for i in range(len(ours)) if ours[i] != theirs[i]]
    assert all(ours[i] == 0 for i in differing), f"bytes {differing[:8]} differ"
    # Read back by rclpy, each is the same message (compared through the writer: NaN != NaN).
    assert writer(deserialize_message(ours, type(msg))) == ours
    assert writer(deserialize_message(theirs, type(msg))) == ours


@pytest.mark.parametrize("ros_class", ROS_CLASSES, ids=lambda cls: cls.__name__)
def test_every_pair_type_is_written_as_rclpy_writes_it(ros_class: type[Any]) -> None:
    assert_same_cdr(filled(ros_class))


def _converted(pair: Pair) -> Any | None:
    try:
        return pair.to_ros(pair.to_gz(filled(pair.ros_class)))
    except ConversionError:
        return None


#: Pairs whose filled message converts both ways; the others refuse one of its values (an
#: enum out of range, say), which their own tests check.
CONVERTING = [pair for pair in PAIRS if _converted(pair) is not None]


@pytest.mark.parametrize("pair", CONVERTING, ids=[f"{p.ros_type}-{p.gz_type}" for p in CONVERTING])
def test_what_each_converter_makes_is_written_as_rclpy_writes_it(pair: Pair) -> None:
    assert_same_cdr(_converted(pair))


def test_most_pairs_give_a_converted_message() -> None:
    assert len(CONVERTING) >= len(PAIRS) * 3 // 4


def test_padding_after_strings_of_every_length() -> None:
    """A string moves the alignment of what follows; every remainder mod 8 is tried."""
    from nav_msgs.msg import Odometry  # noqa: PLC0415

    for length in range(9):
        msg = filled(Odometry)
        msg.header.frame_id = "f" * length
        msg.child_frame_id = "c" * (8 - length)
        assert_same_cdr(msg)


def test_empty_sequences_and_messages() -> None:
    from sensor_msgs.msg import JointState  # noqa: PLC0415
    from std_msgs.msg import Empty  # noqa: PLC0415
    from tf2_msgs.msg import TFMessage  # noqa: PLC0415

    assert_same_cdr(JointState())
    assert_same_cdr(TFMessage())
    assert_same_cdr(Empty())


def test_containers_a_converter_may_leave_are_written_alike() -> None:
    """Lists, tuples and numpy arrays of other dtypes where rclpy keeps array or numpy."""
    from geometry_msgs.msg import PoseWithCovariance  # noqa: PLC0415
    from sensor_msgs.msg import JointState  # noqa: PLC0415

    cov = PoseWithCovariance()
    cov.covariance = np.arange(36, dtype=np.float32) * 0.5
    assert_same_cdr(cov)
    joints = JointState(name=["a", "bb"], position=[1.5, -2.0], velocity=(0.25,), effort=[])
    assert_same_cdr(joints)


@pytest.mark.parametrize(
    ("what", "make"),
    [
        ("an int32 out of range", lambda: _clock(sec=2**31)),
        ("a negative uint32", lambda: _clock(nanosec=-1)),
        ("a float where an integer is declared", lambda: _clock(sec=1.5)),
    ],
)
def test_values_it_cannot_write_exactly_are_refused(what: str, make: Any) -> None:
    """The writer raises, so the channel hands the message to rclpy, which decides."""
    writer = cdr_writer.writer_for(type(make()))
    assert writer is not None
    with pytest.raises(Exception):  # noqa: B017 - any refusal is a refusal
        writer(make())


def test_a_fixed_array_of_another_length_is_refused() -> None:
    from geometry_msgs.msg import PoseWithCovariance  # noqa: PLC0415

    msg = PoseWithCovariance()
    writer = cdr_writer.writer_for(PoseWithCovariance)
    assert writer is not None
    msg._covariance = np.zeros(35)
    with pytest.raises(ValueError, match="35 elements where 36"):
        writer(msg)


def _clock(**stamp: Any) -> Any:
    from builtin_interfaces.msg import Time  # noqa: PLC0415
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415

    time = Time()
    for name, value in stamp.items():
        object.__setattr__(time, f"_{name}", value)  # what a C extension could leave
    return Clock(clock=time)


def test_a_nested_message_of_another_class_is_refused() -> None:
    """The writer reads the slots behind rclpy's properties, so a nested object of another
    class, even one with the same attribute names, is refused (the channel then hands the
    message to rclpy, which decides)."""
    from geometry_msgs.msg import Pose  # noqa: PLC0415

    msg = Pose()
    msg._position = SimpleNamespace(x=1.0, y=2.0, z=3.0)
    writer = cdr_writer.writer_for(Pose)
    assert writer is not None
    with pytest.raises(AttributeError):
        writer(msg)
