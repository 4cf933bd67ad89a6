"""A bidirectional bridge carries each message once to the other side and never echoes it back.

Both sides publish and subscribe on the same topic. The bridge publishes on the ROS topic it
subscribes to and on the Gazebo topic it subscribes to, so without loop prevention every
message would come back to the side that sent it (and then bounce forever). Each side
publishes right after the other, so the ROS publisher's sequence numbers meet the bridge's
one for one (the loop guard must also look at content, core/loop_guard.py). Two pairs: String
(native both ways where the extension is built) and TFMessage (native Gazebo -> ROS, a
hand-written converter ROS -> Gazebo: the native pump's windows judge the Python side's
samples).
"""

from __future__ import annotations

import time
from collections import Counter
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import pytest
from geometry_msgs.msg import TransformStamped
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.converters.tf2_msgs import tf_message_to_gz, tf_message_to_ros
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


@dataclass(frozen=True)
class Kind:
    """A pair bridged both ways, and how the test makes and reads its messages by a text."""

    ros_class: type[Any]
    ros_type: str
    gz_type: str
    ros_message: Callable[[str], Any]
    ros_text: Callable[[Any], str]
    gz_message: Callable[[str], Any]
    gz_text: Callable[[Any], str]


def _tf(text: str) -> TFMessage:
    return TFMessage(transforms=[TransformStamped(child_frame_id=text)])


def _tf_text(msg: TFMessage) -> str:
    return str(msg.transforms[0].child_frame_id) if msg.transforms else ""


STRING_KIND = Kind(
    String,
    "std_msgs/msg/String",
    STRING,
    lambda text: String(data=text),
    lambda msg: str(msg.data),
    lambda text: message_class(STRING)(data=text),
    lambda msg: str(msg.data),
)
TF_KIND = Kind(
    TFMessage,
    "tf2_msgs/msg/TFMessage",
    "gz.msgs.Pose_V",
    _tf,
    _tf_text,
    lambda text: tf_message_to_gz(_tf(text)),
    lambda msg: _tf_text(tf_message_to_ros(msg)),
)


@pytest.fixture(scope="module", params=[STRING_KIND, TF_KIND], ids=["String", "TFMessage"])
def chat(request: pytest.FixtureRequest) -> Iterator[tuple[str, Kind]]:
    require_peer()
    kind: Kind = request.param
    topic = unique_name("chat")
    bridge = start_bridge(f"{topic}@{kind.ros_type}@{kind.gz_type}", creating=2)
    yield topic, kind
    bridge.stop()


def _texts(inbox: Inbox, text_of: Callable[[Any], str]) -> list[str]:
    return [text_of(msg) for msg, _ in inbox.items()]


def test_each_message_crosses_once_and_never_comes_back(
    chat: tuple[str, Kind], ros_side: RosSide, gz_node: GzNode
) -> None:
    topic, kind = chat
    gz_class = message_class(kind.gz_type)
    gz_inbox = Inbox()
    # ignore_local: this node's own publications are not what we count on the Gazebo side.
    gz_subscription = gz_node.subscribe_typed(
        topic, gz_class, gz_inbox, msg_type=kind.gz_type, ignore_local=True
    )
    gz_publisher = gz_node.advertise(topic, kind.gz_type)
    ros_inbox, ros_subscription = ros_side.subscribe(kind.ros_class, topic)
    ros_publisher: Any = ros_side.run(
        lambda: ros_side.node.create_publisher(kind.ros_class, topic, 10)
    )

    def from_ros() -> list[str]:
        return _texts(ros_inbox, kind.ros_text)

    def from_gz() -> list[str]:
        return _texts(gz_inbox, kind.gz_text)

    try:
        wait_until(gz_publisher.has_connections, WAIT, "the bridge's Gazebo subscription")
        publish_until(
            lambda i: gz_publisher.publish(kind.gz_message(f"warm gz {i}")),
            lambda: any(text.startswith("warm gz") for text in from_ros()),
            "Gazebo -> ROS works",
        )
        publish_until(
            lambda i: ros_publisher.publish(kind.ros_message(f"warm ros {i}")),
            lambda: any(text.startswith("warm ros") for text in from_gz()),
            "ROS -> Gazebo works",
        )
        time.sleep(ECHO_WINDOW)
        ros_inbox.clear()
        gz_inbox.clear()

        for index in range(BATCH):
            gz_publisher.publish(kind.gz_message(f"gz {index}"))
            ros_publisher.publish(kind.ros_message(f"ros {index}"))
            time.sleep(0.05)
        gz_batch = {f"gz {index}" for index in range(BATCH)}
        ros_batch = {f"ros {index}" for index in range(BATCH)}
        ros_inbox.wait_for(
            lambda items: gz_batch <= {kind.ros_text(m) for m, _ in items},
            WAIT,
            "the Gazebo batch in ROS",
        )
        gz_inbox.wait_for(
            lambda items: ros_batch <= {kind.gz_text(m) for m, _ in items},
            WAIT,
            "the ROS batch in Gazebo",
        )
        time.sleep(ECHO_WINDOW)

        # ROS sees its own publisher's messages once (directly) and Gazebo's once (bridged).
        assert Counter(from_ros()) == Counter(gz_batch | ros_batch)
        # Gazebo sees ROS's messages once and none of its own coming back.
        assert Counter(from_gz()) == Counter(ros_batch)
    finally:
        gz_subscription.close()
        gz_publisher.close()
        ros_side.destroy(ros_subscription)
        ros_side.destroy(ros_publisher)
