"""Every native ROS -> Gazebo channel of a process runs on one loop thread (docs/native.md §7).

An embedded bridge (its own rclpy node and a Gazebo node the embedder made) carries 30
``std_msgs/String`` channels to this test's Gazebo node and one to the C++ Fortress peer: the
process gains no thread per channel, and every channel's messages arrive. A flooded channel
does not starve a 10 Hz one beside it, and an embedder that closes its Gazebo node while ROS
messages flow takes the loop off the node's sockets first (no send on a freed socket).
"""

from __future__ import annotations

import os
import threading
import time
import uuid
from collections.abc import Iterator
from typing import Any

import pytest
import rclpy
from std_msgs.msg import String

from ros_gz_bridge_py import Bridge
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.bridge import BridgeOptions
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.loop import ROS_TO_GZ, shared_loop
from ros_gz_bridge_py.transport import GzNode, create_gz_node
from ros_gz_bridge_py.transport.api import MessageInfo
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_node,
    publish_until,
    ros_side,
    started,
)
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    unique_name,
    wait_for_line,
    wait_until,
)

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

CHANNELS = 30
#: Messages of the 10 Hz channel while the other floods.
STEADY = 30


class Received:
    """The payloads a Gazebo subscription got, from its receiving thread."""

    def __init__(self) -> None:
        self.payloads: list[bytes] = []
        self._lock = threading.Lock()

    def __call__(self, payload: Any, _info: MessageInfo) -> None:
        with self._lock:
            self.payloads.append(bytes(payload))

    def texts(self) -> list[str]:
        with self._lock:
            return [string_data(p) for p in self.payloads]

    def __len__(self) -> int:
        with self._lock:
            return len(self.payloads)


def string_data(payload: bytes) -> str:
    """The ``data`` of an ``ignition.msgs.StringMsg``."""
    msg = message_class(STRING)()
    msg.ParseFromString(payload)
    return str(msg.data)


def spec(topic: str) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, Direction.ROS_TO_GZ)


def os_threads() -> int:
    return len(os.listdir("/proc/self/task"))


@pytest.fixture
def embedder_gz_node() -> Iterator[GzNode]:
    node = create_gz_node()
    yield node
    node.close()


@pytest.fixture
def bridge(ros_side: RosSide, embedder_gz_node: GzNode) -> Iterator[Bridge]:
    """A bridge on a node of its own in the test's context, with the embedder's Gazebo node."""
    require_peer()
    if extension() is None:
        pytest.skip("the native extension is not built here")
    node: Any = rclpy.create_node(f"shared_loop_{uuid.uuid4().hex[:8]}", context=ros_side.context)
    embedded = Bridge(node, gz_node=embedder_gz_node, options=BridgeOptions(heartbeat=0.2))
    yield embedded
    embedded.close()
    node.destroy_node()


def test_thirty_channels_run_on_one_loop_thread_and_all_deliver(
    bridge: Bridge, ros_side: RosSide, gz_node: GzNode, started: list[PeerProcess]
) -> None:
    topics = [unique_name(f"fleet_{index}") for index in range(CHANNELS)]
    inboxes = {topic: Received() for topic in topics}
    for topic in topics:
        gz_node.subscribe(topic, inboxes[topic], STRING)
    fortress = start_peer("echo", topics[0], STRING, str(WAIT * 2), "--count", "1")
    started.append(fortress)
    wait_for_line(fortress, "^READY", timeout=WAIT)
    python_threads, threads = len(threading.enumerate()), os_threads()
    running = shared_loop(ROS_TO_GZ).thread is not None  # an earlier bridge's

    for topic in topics:
        bridge.add(spec(topic))
    assert all(channel.native for channel in bridge.channels)
    publishers = [
        ros_side.run(lambda t=topic: ros_side.node.create_publisher(String, t, 10))  # type: ignore[misc]
        for topic in topics
    ]
    for topic, publisher in zip(topics, publishers, strict=True):
        publish_until(
            lambda i, p=publisher, t=topic: ros_side.run(  # type: ignore[misc]
                lambda: p.publish(String(data=f"{t} {i}"))
            ),
            lambda t=topic: len(inboxes[t]) > 0,  # type: ignore[misc]
            f"a message on {topic}",
        )
    wait_for_line(fortress, rf'^MSG {STRING} data: "{topics[0]} \d+"', timeout=WAIT)

    names = [thread.name for thread in threading.enumerate()]
    assert names.count(ROS_TO_GZ) == 1
    assert not [name for name in names if name.startswith("ros-pub")]
    assert len(names) <= python_threads + 1 - running  # the loop's own, none per channel
    # nothing per channel (the loop's own; a middleware thread may start)
    assert os_threads() <= threads + 3 - running
    assert shared_loop(ROS_TO_GZ).size() >= CHANNELS
    for topic in topics:
        assert all(text.startswith(f"{topic} ") for text in inboxes[topic].texts())


def test_a_flooded_channel_does_not_starve_a_10_hz_one(
    bridge: Bridge, ros_side: RosSide, gz_node: GzNode
) -> None:
    flood_topic, steady_topic = unique_name("flood"), unique_name("steady")
    flooded, steady = Received(), Received()
    gz_node.subscribe(flood_topic, flooded, STRING)
    gz_node.subscribe(steady_topic, steady, STRING)
    bridge.add(spec(flood_topic))
    bridge.add(spec(steady_topic))
    flood_pub = ros_side.run(lambda: ros_side.node.create_publisher(String, flood_topic, 1000))
    steady_pub = ros_side.run(lambda: ros_side.node.create_publisher(String, steady_topic, 10))
    publish_until(
        lambda i: ros_side.run(lambda: steady_pub.publish(String(data=f"warm-up {i}"))),
        lambda: len(steady) > 0,
        "the steady channel",
    )
    publish_until(
        lambda i: ros_side.run(lambda: flood_pub.publish(String(data=f"warm-up {i}"))),
        lambda: len(flooded) > 0,
        "the flooded channel",
    )
    stop = threading.Event()
    sent = [0]

    def flood() -> None:
        message = String(data="x" * 64)
        while not stop.is_set():
            flood_pub.publish(message)
            sent[0] += 1

    flooder = threading.Thread(target=flood, name="test-flood", daemon=True)
    flooder.start()
    try:
        before = len(flooded)
        for index in range(STEADY):
            steady_pub.publish(String(data=f"steady {index}"))
            time.sleep(0.1)
        wait_until(
            lambda: sum(t.startswith("steady ") for t in steady.texts()) == STEADY,
            WAIT,
            "every 10 Hz message",
        )
        during = len(flooded) - before
    finally:
        stop.set()
        flooder.join()
    texts = [t for t in steady.texts() if t.startswith("steady ")]
    assert texts == [f"steady {index}" for index in range(STEADY)]
    assert during > 10 * STEADY, f"the flood ran ({sent[0]} sent, {during} arrived meanwhile)"


def test_an_embedder_closes_its_gz_node_while_ros_messages_flow(
    bridge: Bridge, ros_side: RosSide, gz_node: GzNode, embedder_gz_node: GzNode
) -> None:
    topic = unique_name("closing")
    received = Received()
    gz_node.subscribe(topic, received, STRING)
    bridge.add(spec(topic))
    attached = shared_loop(ROS_TO_GZ).size()
    publisher = ros_side.run(lambda: ros_side.node.create_publisher(String, topic, 1000))
    publish_until(
        lambda i: ros_side.run(lambda: publisher.publish(String(data=f"warm-up {i}"))),
        lambda: len(received) > 0,
        "the channel",
    )
    stop = threading.Event()

    def flood() -> None:
        message = String(data="y" * 64)
        while not stop.is_set():
            publisher.publish(message)

    flooder = threading.Thread(target=flood, name="test-flood", daemon=True)
    flooder.start()
    try:
        wait_until(lambda: len(received) > 100, WAIT, "the flood arriving")
        embedder_gz_node.close()  # its sockets go; the loop must not send on them after
        assert shared_loop(ROS_TO_GZ).size() == attached - 1
        time.sleep(0.5)  # messages keep coming to the subscription no loop takes from now
    finally:
        stop.set()
        flooder.join()
    # Taken off before its socket went, not by the failure of a send on a closed socket:
    assert [channel.stats.last_error for channel in bridge.channels] == [""]
    bridge.close()  # after the node: closes the channels without sending


def test_own_publications_skipped_by_the_native_loop_are_not_received(
    bridge: Bridge, started: list[PeerProcess]
) -> None:
    """The native loop counted a bidirectional topic's own publications, which it skips, as
    received: IN ran ahead of OUT by them in the status table (the Python path does not)."""
    topic = unique_name("native_own")
    handle = bridge.add(TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING))
    to_ros, to_gz = handle.channels
    assert to_gz.native, "the ROS->Gazebo half takes the native loop"
    publisher = start_peer("pub", topic, STRING, "50", "0", 'data: "from gazebo"', "--wait", "60")
    started.append(publisher)
    wait_for_line(publisher, r"^READY$")
    wait_until(lambda: to_gz.stats.own_skipped >= 10, WAIT * 2, "own publications skipped")
    wait_until(lambda: to_ros.stats.published >= 10, WAIT, "Gazebo's messages published")
    assert (to_gz.stats.received, to_gz.stats.published) == (0, 0)
