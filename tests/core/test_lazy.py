"""Lazy channels in one process: the input side is open only while the output side has a
reader other than the bridge itself, in both directions, and the heartbeat re-checks.

Most tests call the heartbeat themselves (the test bridge's timer is an hour), so each check
happens at a known point; one test lets the bridge's own timer do it.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import pytest
from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.channel import Channel, ChannelState
from ros_gz_bridge_py.msgs import message_class
from tests.core.harness import (
    Inbox,
    Rig,
    RosWorld,
    gz_to_ros,
    options,
    publish_until,
    ros_to_gz,
    settled,
    unique,
    wait_until,
)

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING = "gz.msgs.StringMsg"
GzString = message_class(STRING)


def spec(topic: str, direction: Direction, lazy: bool | None = True) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, direction, lazy=lazy)


def state_of(channel: Channel) -> ChannelState:
    """The channel's state now (read anew: the bridge changes it)."""
    return channel.state


def input_open(channel: Channel) -> bool:
    """The input side is open (ACTIVE; a lazy channel without readers is LAZY_IDLE)."""
    return channel.state is ChannelState.ACTIVE


def heartbeat_until(rig: Rig, condition: Callable[[], bool], what: str) -> None:
    """Re-check as the timer would until ``condition``: the ROS graph shows a new or gone
    endpoint a moment after it changed, even in one process."""

    def checked() -> bool:
        rig.heartbeat()
        return condition()

    wait_until(checked, what)


def test_gazebo_to_ros_subscribes_to_gazebo_only_while_ros_reads(rig: Rig, world: RosWorld) -> None:
    topic = unique("lazy_g2r")
    channel = gz_to_ros(rig.add(spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    assert state_of(channel) is ChannelState.LAZY_IDLE
    rig.heartbeat()
    assert not input_open(channel)
    assert not publisher.has_connections()

    inbox, subscription = world.subscribe(String, topic)
    heartbeat_until(rig, publisher.has_connections, "the Gazebo subscription after a ROS reader")
    assert state_of(channel) is ChannelState.ACTIVE
    sent = publish_until(
        lambda i: publisher.publish(GzString(data=f"lazy {i}")),
        lambda: bool(inbox.messages()),
        "the ROS reader receives",
    )
    settled(channel, sent)
    assert inbox.messages()[0].data.startswith("lazy ")

    world.destroy(subscription)
    heartbeat_until(rig, lambda: not publisher.has_connections(), "the Gazebo unsubscription")
    assert state_of(channel) is ChannelState.LAZY_IDLE
    publisher.publish(GzString(data="nobody reads this"))
    assert channel.stats.received == sent  # closed: nothing more reaches the channel


def test_ros_to_gazebo_subscribes_to_ros_only_while_gazebo_reads(rig: Rig, world: RosWorld) -> None:
    topic = unique("lazy_r2g")
    channel = ros_to_gz(rig.add(spec(topic, Direction.ROS_TO_GZ)))
    assert rig.gazebo().topic_info(topic), "the Gazebo side is advertised while idle"
    rig.heartbeat()
    assert state_of(channel) is ChannelState.LAZY_IDLE
    assert world.subscribers(topic) == []

    inbox = Inbox()
    gz_subscription = rig.gazebo().subscribe_typed(topic, GzString, inbox)
    heartbeat_until(rig, lambda: input_open(channel), "the input side after a Gazebo reader")
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the bridge's ROS subscription")
    publisher = world.publisher(String, topic)
    sent = publish_until(
        lambda i: publisher.publish(String(data=f"to gazebo {i}")),
        lambda: bool(inbox.messages()),
        "the Gazebo reader receives",
    )
    settled(channel, sent)
    assert inbox.messages()[0].data.startswith("to gazebo ")

    gz_subscription.close()
    rig.heartbeat()  # Gazebo registrations are known at once: no waiting for a graph
    assert state_of(channel) is ChannelState.LAZY_IDLE
    wait_until(lambda: world.subscribers(topic) == [], "the bridge's ROS subscription gone")


def test_the_bridges_own_subscription_is_not_a_reader(rig: Rig, world: RosWorld) -> None:
    """A non-lazy ROS->Gazebo entry on the same ROS topic subscribes it (on the bridge's
    side node, with the loop guard); that must not wake the lazy Gazebo->ROS entry."""
    topic = unique("lazy_own")
    lazy = gz_to_ros(rig.add(spec(topic, Direction.GZ_TO_ROS)))
    eager = ros_to_gz(rig.add(spec(topic, Direction.ROS_TO_GZ, lazy=False)))
    assert eager.loop_guard
    assert input_open(eager)
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the bridge's own ROS subscription")
    rig.heartbeat()
    assert state_of(lazy) is ChannelState.LAZY_IDLE

    _, subscription = world.subscribe(String, topic)
    heartbeat_until(rig, lambda: input_open(lazy), "a reader of another node wakes it")
    world.destroy(subscription)
    heartbeat_until(rig, lambda: not input_open(lazy), "idle again without it")


def test_laziness_comes_from_the_entry_else_the_node(make_rig: Any) -> None:
    rig: Rig = make_rig(options(lazy=True))
    by_node = rig.add(spec(unique("node_lazy"), Direction.BIDIRECTIONAL, lazy=None))
    eager = rig.add(spec(unique("entry_eager"), Direction.BIDIRECTIONAL, lazy=False))
    assert [c.lazy for c in by_node.channels] == [True, True]
    assert [c.state for c in by_node.channels] == [ChannelState.LAZY_IDLE] * 2
    assert [c.lazy for c in eager.channels] == [False, False]
    assert [c.state for c in eager.channels] == [ChannelState.ACTIVE] * 2


def test_the_heartbeat_timer_rechecks_by_itself(make_rig: Any, world: RosWorld) -> None:
    rig: Rig = make_rig(options(heartbeat=0.05))
    topic = unique("lazy_timer")
    channel = gz_to_ros(rig.add(spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    assert not publisher.has_connections()
    _, subscription = world.subscribe(String, topic)
    # The state changes once the timer's check has finished opening or closing.
    wait_until(lambda: state_of(channel) is ChannelState.ACTIVE, "the timer to open the input side")
    assert publisher.has_connections()
    world.destroy(subscription)
    wait_until(lambda: state_of(channel) is ChannelState.LAZY_IDLE, "the timer to close it again")
    assert not publisher.has_connections()
