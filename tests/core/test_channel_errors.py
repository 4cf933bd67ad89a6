"""Every message a Gazebo->ROS channel cannot use is counted under what was wrong, shown in the
status table and ``/diagnostics`` values, and warned about (issue 14, point 3).

In-process: the bridge on the memory backend (a maximum message size of 1000 bytes) and an
rclpy node of its own context; another memory node plays the Gazebo publishers.
"""

from __future__ import annotations

import dataclasses
import uuid
from collections.abc import Iterator
from typing import Any, cast

import pytest
import rclpy
from rclpy.context import Context

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.bridge import Bridge, BridgeOptions
from ros_gz_bridge_py.core.channel import Channel, conversion_reason
from ros_gz_bridge_py.core.status import channel_status, diagnostic_array, format_table
from ros_gz_bridge_py.errors import ConversionError, SizeMismatchError, UndecodableError
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import Rejection, TransportSettings
from ros_gz_bridge_py.transport.memory.network import MemoryNetwork
from ros_gz_bridge_py.transport.memory.node import MemoryGzNode
from testing.polling import wait_until

STRING = "gz.msgs.StringMsg"
IMAGE = "gz.msgs.Image"
StringMsg = message_class(STRING)
GzImage = message_class(IMAGE)
LIMIT = 1000
RGB_INT8 = 3


class Setup:
    def __init__(self) -> None:
        self.context = Context()
        rclpy.init(context=self.context)
        name = f"errors_{uuid.uuid4().hex[:6]}"
        self.ros_node: Any = rclpy.create_node(name, context=self.context)
        network = MemoryNetwork()
        settings = dataclasses.replace(TransportSettings.from_env(), max_message_size=LIMIT)
        self.gz_bridge_node = MemoryGzNode(settings=settings, network=network)
        self.gazebo = MemoryGzNode(network=network)
        self.bridge = Bridge(
            self.ros_node, gz_node=self.gz_bridge_node, options=BridgeOptions(explain=False)
        )
        self.warnings: list[str] = []

    def channel(self, topic: str, ros_type: str, gz_type: str) -> Channel:
        spec = TopicBridgeSpec(
            ros_topic=topic,
            gz_topic=topic,
            ros_type=ros_type,
            gz_type=gz_type,
            direction=Direction.GZ_TO_ROS,
        )
        channel = self.bridge.add(spec).channels[0]
        channel._logger = cast(Any, self)  # collect its warnings
        return channel

    def warning(self, text: str) -> None:
        self.warnings.append(text)

    def close(self) -> None:
        self.bridge.close()
        self.gazebo.close()
        self.gz_bridge_node.close()
        self.ros_node.destroy_node()
        rclpy.try_shutdown(context=self.context)


@pytest.fixture
def setup() -> Iterator[Setup]:
    made = Setup()
    yield made
    made.close()


def test_each_kind_of_bad_message_is_counted_shown_and_warned_about(setup: Setup) -> None:
    topic = f"/errors_{uuid.uuid4().hex[:6]}"
    channel = setup.channel(topic, "std_msgs/msg/String", STRING)
    publisher = setup.gazebo.advertise(topic, STRING)
    # A generic subscriber in a third process makes the Int32 publisher send (gz publishes
    # only to registered subscribers); the bridge's String channel then gets another type.
    listener = MemoryGzNode(network=setup.gazebo.network)
    listener.subscribe(topic, lambda *_: None, queue_size=10)
    other = setup.gazebo.advertise(topic, "gz.msgs.Int32")
    assert wait_until(lambda: publisher.has_connections() and other.has_connections())
    sent = {"undecodable payload": 7, "wrong type": 5, "over the size limit": 3}
    for _ in range(sent["undecodable payload"]):
        publisher.publish_raw(b"\x0a\xff")  # a length past the end
    for _ in range(sent["wrong type"]):
        other.publish(message_class("gz.msgs.Int32")(data=1))
    for _ in range(sent["over the size limit"]):
        publisher.publish(StringMsg(data="x" * 2 * LIMIT))
    publisher.publish(StringMsg(data="fine"))
    assert wait_until(lambda: channel.stats.published == 1 and channel.stats.errors == 15)
    assert channel.stats.errors_by_reason == sent
    assert (channel.stats.conversion_errors, channel.stats.rejected) == (7, 8)

    status = channel_status(channel)
    assert status.errors == 15
    assert status.error_summary() == "7 undecodable payload, 5 wrong type, 3 over the size limit"
    table = format_table([status])
    assert f"errors GZ->ROS {topic}: 7 undecodable payload, 5 wrong type, 3" in table
    values = {kv.key: kv.value for kv in diagnostic_array([status], "h", None).status[0].values}
    assert (values["errors"], values["errors: wrong type"]) == ("15", "5")
    assert values["errors: over the size limit"] == "3"
    # One warning per kind (throttled), each saying what was wrong and where to look.
    assert len(setup.warnings) == 3
    assert any("(wrong type)" in w and "gz.msgs.Int32" in w for w in setup.warnings)
    assert any("GZ_TRANSPORT_MAX_MESSAGE_SIZE" in w for w in setup.warnings)
    listener.close()


def test_inconsistent_image_sizes_have_their_own_reason(setup: Setup) -> None:
    topic = f"/image_{uuid.uuid4().hex[:6]}"
    channel = setup.channel(topic, "sensor_msgs/msg/Image", IMAGE)
    publisher = setup.gazebo.advertise(topic, IMAGE)
    assert wait_until(publisher.has_connections)
    short = GzImage(width=10, height=10, pixel_format_type=RGB_INT8, data=bytes(30))
    publisher.publish(short)
    assert wait_until(lambda: channel.stats.errors == 1)
    assert channel.stats.errors_by_reason == {"inconsistent sizes": 1}
    assert "fewer than height*step" in channel.stats.last_error


def test_conversion_reasons() -> None:
    assert conversion_reason(UndecodableError("x")) is Rejection.UNDECODABLE
    assert conversion_reason(SizeMismatchError("x")) is Rejection.INCONSISTENT_SIZES
    assert conversion_reason(ConversionError("x")) is Rejection.CONVERSION
    assert conversion_reason(ValueError("x")) is Rejection.CONVERSION
