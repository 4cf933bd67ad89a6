"""The side node (``ros/side_node.py``): its thread outlives bridges removed while messages
flow, and a closed bridge leaves none of its threads behind (both found by a new user
embedding the bridge)."""

from __future__ import annotations

import threading
from typing import Any

from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.msgs import message_class
from tests.core.harness import Inbox, Rig, RosWorld, publish_until, unique

STRING = "gz.msgs.StringMsg"
#: Bridges added and removed while a ROS publisher writes at 2 kHz: rclpy raised InvalidHandle
#: into the side node's thread, which ended it, in about one run of three of this test.
CHURN = 400


def side_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name == "ros-gz-side"]


def test_the_side_thread_outlives_bridges_removed_while_messages_flow(
    world: RosWorld, rig: Rig
) -> None:
    topic = unique("churn")
    spec = TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, Direction.BIDIRECTIONAL)
    publisher = world.publisher(String, topic)
    stop = threading.Event()

    def publish() -> None:
        while not stop.wait(0.0005):
            publisher.publish(String(data="churn"))

    writer = threading.Thread(target=publish, name="churn-writer")
    writer.start()
    try:
        for _ in range(CHURN):
            rig.remove(rig.add(spec))
            assert side_threads() == ["ros-gz-side"]
    finally:
        stop.set()
        writer.join()
    # the side node still carries a loop-guarded channel's messages
    rig.add(spec)
    inbox = Inbox()
    rig.gazebo().subscribe_typed(topic, message_class(STRING), inbox, ignore_local=True)
    publish_until(
        lambda i: publisher.publish(String(data=f"after {i}")),
        lambda: bool(inbox.messages()),
        "a message through the side node after the churn",
    )


def run_one_callback(world: RosWorld, rig: Rig, topic: str) -> None:
    """A bidirectional bridge of ``topic`` whose side node takes ROS messages."""
    handle = rig.add(TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING))
    publisher = world.publisher(String, topic)

    def publish(index: int) -> None:
        publisher.publish(String(data=str(index)))

    def received() -> bool:
        return any(channel.stats.received for channel in handle.channels)

    publish_until(publish, received, "a callback of the side node")
    world.destroy(publisher)


def test_a_closed_bridge_leaves_no_thread_of_its_side_node(world: RosWorld, make_rig: Any) -> None:
    """rclpy's MultiThreadedExecutor kept its worker pool after shutdown(): idle threads for
    each bridge closed whose side node had run a callback."""
    before = set(threading.enumerate())
    for _ in range(3):
        rig = make_rig()
        topic = unique("closed")
        run_one_callback(world, rig, topic)
        rig.close()
    left = [t.name for t in set(threading.enumerate()) - before if t.is_alive()]
    assert left == []
