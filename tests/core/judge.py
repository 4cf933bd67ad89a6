"""The explainer of one rig's channels, with a clock the test moves, and what the explanation
tests share (``test_explain.py``: the Gazebo side; ``test_explain_ros_side.py``)."""

from __future__ import annotations

from typing import Any

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.channel import Channel
from ros_gz_bridge_py.core.diagnosis import Flow
from ros_gz_bridge_py.core.explain import (
    CONFIRM_AFTER,
    WARM_UP,
    Explainer,
)
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.ros.side_node import side_node_name
from tests.core.harness import Inbox, Rig, publish_until, settled

STRING = "gz.msgs.StringMsg"
GzString = message_class(STRING)


class Judge:
    """An explainer of one rig's channels, with its own clock and log."""

    def __init__(self, rig: Rig) -> None:
        self.rig = rig
        self.now = 500.0
        self.logged: list[str] = []  # warnings
        self.noted: list[str] = []  # sides not there yet
        node = rig.node
        own = {
            (node.get_name(), node.get_namespace()),
            (side_node_name(node), node.get_namespace()),
        }
        self.explainer = Explainer(
            rig.gz,
            rig.bridge.registry,
            own,
            self.logged.append,
            now=lambda: self.now,
            note=self.noted.append,
        )

    def evaluate(self, after: float = 0.0) -> None:
        """Move the clock by ``after`` seconds and evaluate every channel of the bridge."""
        self.now += after
        channels = self.rig.bridge.channels
        self.rig.world.run(lambda: self.explainer.evaluate(channels))

    def until_confirmed(self) -> None:
        """Evaluate now, past the warm-up and past the confirmation: a cause that lasted
        through all three is logged by the last."""
        self.evaluate()
        self.evaluate(WARM_UP)
        self.evaluate(CONFIRM_AFTER)


def spec(
    topic: str, direction: Direction, ros_type: str, gz_type: str, **fields: Any
) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, ros_type, gz_type, direction, **fields)


def string_spec(topic: str, direction: Direction, **fields: Any) -> TopicBridgeSpec:
    return spec(topic, direction, "std_msgs/msg/String", STRING, **fields)


def texts(channel: Channel) -> list[str]:
    return [finding.text for finding in channel.findings]


def flow_of(channel: Channel) -> Flow | None:
    """The channel's flow as the last evaluation set it."""
    return channel.flow


def carry(channel: Channel, publisher: Any, inbox: Inbox) -> None:
    """Publish Gazebo strings on ``publisher`` until ``inbox`` (a ROS subscriber of the
    channel's topic) has one, and wait until the channel handled each."""
    sent = publish_until(
        lambda i: publisher.publish(GzString(data=str(i))),
        lambda: bool(inbox.messages()),
        "a message in ROS",
    )
    settled(channel, sent)
