"""Gazebo -> ROS channels publish the same messages with the CDR writer as through rclpy.

The writer's bytes are compared with rclpy's for every pair in tests/unit/ros/test_cdr_writer.py;
here a real channel publishes them through rcl (GIL released) to a real rclpy subscription,
and what arrives is compared with what the same channel publishes with ``cdr_write`` off. A
message the writer refuses goes through rclpy's publish and arrives as rclpy makes it.
"""

from __future__ import annotations

from typing import Any

import pytest
from nav_msgs.msg import Odometry
from rclpy.serialization import serialize_message
from rosgraph_msgs.msg import Clock

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.ros.serialized_publisher import (
    SerializedPublisher,
    WrittenPublisher,
    object_publisher,
)
from tests.core.harness import (
    RosWorld,
    gz_to_ros,
    options,
    publish_until,
    settled,
    unique,
)
from tests.ros_values import filled

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

ODOMETRY = default_registry().get("nav_msgs/msg/Odometry", "gz.msgs.Odometry")
BATCH = 5


def odometry(child_frame_id: str) -> Any:
    """A Gazebo Odometry with distinctive values."""
    ros = filled(Odometry)
    ros.child_frame_id = child_frame_id
    return ODOMETRY.to_gz(ros)


def received_through_channel(make_rig: Any, world: RosWorld, *, cdr_write: bool) -> list[Any]:
    rig = make_rig(options(cdr_write=cdr_write))
    topic = unique("g2r_odometry")
    spec = TopicBridgeSpec(topic, topic, "nav_msgs/msg/Odometry", "gz.msgs.Odometry",
                           Direction.GZ_TO_ROS)  # fmt: skip
    channel = gz_to_ros(rig.add(spec))
    publisher = rig.gazebo().advertise(topic, "gz.msgs.Odometry")
    inbox, _ = world.subscribe(Odometry, topic)
    warm = publish_until(
        lambda i: publisher.publish(odometry(f"warm_{i}")), lambda: bool(inbox.messages()), "one"
    )
    for index in range(BATCH):
        publisher.publish(odometry(f"base_{index}"))
    settled(channel, warm + BATCH)
    received = inbox.wait_for(lambda got: len(got) >= warm + BATCH, "the batch in ROS")
    return [m for m in received if m.child_frame_id.startswith("base_")]


def test_written_and_rclpy_published_messages_arrive_alike(make_rig: Any, world: RosWorld) -> None:
    written = received_through_channel(make_rig, world, cdr_write=True)
    through_rclpy = received_through_channel(make_rig, world, cdr_write=False)
    assert len(written) == BATCH
    assert written == through_rclpy


def test_every_type_of_a_pair_without_a_bulk_path_gets_a_writer() -> None:
    """What a Gazebo -> ROS channel of each non-bulk pair publishes with."""
    classes = {pair.ros_class for pair in default_registry().pairs if pair.bulk is None}
    publisher = _FakePublisher()
    kinds = {type(object_publisher(publisher, cls, through_rcl=False)) for cls in classes}
    assert kinds == {WrittenPublisher}


def test_a_message_the_writer_refuses_is_published_by_rclpy(world: RosWorld) -> None:
    topic = unique("clock_fallback")
    publisher = world.publisher(Clock, topic)
    inbox, _ = world.subscribe(Clock, topic)
    written = object_publisher(publisher, Clock, through_rcl=True)
    assert isinstance(written, WrittenPublisher)

    def out_of_range(index: int) -> Any:
        msg = Clock()
        msg.clock.nanosec = index
        object.__setattr__(msg.clock, "_sec", 2**40 + 7)  # past rclpy's setter
        return msg

    publish_until(lambda i: written.publish(out_of_range(i)), lambda: bool(inbox.messages()), "")
    assert written.fallbacks >= 1
    # rclpy's own conversion keeps the low 32 bits; the fallback shows what rclpy does.
    assert inbox.messages()[0].clock.sec == 7


@pytest.mark.parametrize("through_rcl", [True, False])
def test_serialized_views_are_published_as_their_bytes(world: RosWorld, through_rcl: bool) -> None:
    """The bulk path hands a view of the received frame (written in place) or bytes; rcl
    takes a writable view's memory as it is, a read-only view and rclpy's way take bytes."""
    topic = unique("clock_views")
    publisher = world.publisher(Clock, topic)
    inbox, _ = world.subscribe(Clock, topic)
    serialized = SerializedPublisher(publisher, through_rcl=through_rcl)

    def cdr(sec: int) -> bytes:
        msg = Clock()
        msg.clock.sec = sec
        return bytes(serialize_message(msg))

    frame = bytearray(b"header" + cdr(11) + b"trailer")  # the CDR inside a larger buffer
    in_frame = memoryview(frame)[6:-7]
    publish_until(lambda _i: serialized.publish(in_frame), lambda: bool(inbox.messages()), "")
    serialized.publish(memoryview(cdr(12)))
    serialized.publish(cdr(13))
    got = inbox.wait_for(lambda got: {12, 13} <= {m.clock.sec for m in got}, "the views")
    assert {m.clock.sec for m in got} == {11, 12, 13}


class _FakePublisher:
    """Only what :func:`object_publisher` reads before publishing."""

    class _Handle:
        pointer = 0

    handle = _Handle()
    topic_name = "/fake"

    def publish(self, _msg: Any) -> None:  # pragma: no cover - never published
        raise AssertionError
