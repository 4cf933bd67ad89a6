"""A bidirectional bridge carries each message once to the other side and never echoes it back.

Both sides publish and subscribe on the same topic. The bridge publishes on the ROS topic it
subscribes to and on the Gazebo topic it subscribes to, so without loop prevention every
message would come back to the side that sent it (and then bounce forever).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Iterator
from typing import Any

import pytest
from std_msgs.msg import String

from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_node,
    publish_until,
    ros_side,
    start_bridge,
)
from testing.gzpeer import Inbox, require_peer, unique_name, wait_until

__all__ = ["gz_node", "ros_side"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

BATCH = 10
#: After everything expected arrived, how long to keep listening for echoes.
ECHO_WINDOW = 1.5


@pytest.fixture(scope="module")
def chat() -> Iterator[str]:
    require_peer()
    topic = unique_name("chat")
    bridge = start_bridge(f"{topic}@std_msgs/msg/String@{STRING}", creating=2)
    yield topic
    bridge.stop()


def _data(inbox: Inbox) -> list[str]:
    return [msg.data for msg, _ in inbox.items()]


def test_each_message_crosses_once_and_never_comes_back(
    chat: str, ros_side: RosSide, gz_node: GzNode
) -> None:
    string_msg = message_class(STRING)
    gz_inbox = Inbox()
    # ignore_local: this node's own publications are not what we count on the Gazebo side.
    gz_subscription = gz_node.subscribe_typed(
        chat, string_msg, gz_inbox, msg_type=STRING, ignore_local=True
    )
    gz_publisher = gz_node.advertise(chat, STRING)
    ros_inbox, ros_subscription = ros_side.subscribe(String, chat)
    ros_publisher: Any = ros_side.run(lambda: ros_side.node.create_publisher(String, chat, 10))
    try:
        wait_until(gz_publisher.has_connections, WAIT, "the bridge's Gazebo subscription")
        publish_until(
            lambda i: gz_publisher.publish(string_msg(data=f"warm gz {i}")),
            lambda: any(d.startswith("warm gz") for d in _data(ros_inbox)),
            "Gazebo -> ROS works",
        )
        publish_until(
            lambda i: ros_publisher.publish(String(data=f"warm ros {i}")),
            lambda: any(d.startswith("warm ros") for d in _data(gz_inbox)),
            "ROS -> Gazebo works",
        )
        time.sleep(ECHO_WINDOW)
        ros_inbox.clear()
        gz_inbox.clear()

        for index in range(BATCH):
            gz_publisher.publish(string_msg(data=f"gz {index}"))
            ros_publisher.publish(String(data=f"ros {index}"))
            time.sleep(0.05)
        from_gz = {f"gz {index}" for index in range(BATCH)}
        from_ros = {f"ros {index}" for index in range(BATCH)}
        ros_inbox.wait_for(
            lambda items: from_gz <= {m.data for m, _ in items}, WAIT, "the Gazebo batch in ROS"
        )
        gz_inbox.wait_for(
            lambda items: from_ros <= {m.data for m, _ in items}, WAIT, "the ROS batch in Gazebo"
        )
        time.sleep(ECHO_WINDOW)

        # ROS sees its own publisher's messages once (directly) and Gazebo's once (bridged).
        assert Counter(_data(ros_inbox)) == Counter(from_gz | from_ros)
        # Gazebo sees ROS's messages once and none of its own coming back.
        assert Counter(_data(gz_inbox)) == Counter(from_ros)
    finally:
        gz_subscription.close()
        gz_publisher.close()
        ros_side.destroy(ros_subscription)
        ros_side.destroy(ros_publisher)
