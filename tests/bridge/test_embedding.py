"""Embedding ``Bridge`` in a program: the example end to end, a program that shuts ROS down
first, and add/remove in-process.

``examples/embed_bridge.py`` runs as a subprocess next to two real ign-transport 11
publishers. In-process, ``Bridge.add``/``remove`` are checked from the outside: a removed
Gazebo->ROS bridge leaves no Gazebo subscription and no ROS publisher behind, a removed
ROS->Gazebo bridge no ROS subscription and no Gazebo advertisement.
"""

from __future__ import annotations

import signal
import sys
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rclpy

from ros_gz_bridge_py import Bridge, BridgeOptions
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_advertised,
    gz_node,
    ros_side,
    started,
    wait_gz_advertised,
)
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "embed_bridge.py"


def test_example_bridges_removes_and_bridges_again(started: list[PeerProcess]) -> None:
    require_peer()
    first, second = unique_name("embed_first"), unique_name("embed_second")
    for topic, text in ((first, "from gazebo one"), (second, "from gazebo two")):
        publisher = start_peer("pub", topic, STRING, "10", "0", f'data: "{text}"', "--wait", "60")
        started.append(publisher)
        wait_for_line(publisher, r"^READY$")
    example = start_process(
        [sys.executable, str(EXAMPLE), "--first", first, "--second", second,
         "--gz-type", STRING, "--timeout", str(WAIT)]
    )  # fmt: skip
    started.append(example)

    wait_for_line(example, rf"^ADDED {first}$", timeout=30)
    wait_for_line(example, rf"^RECEIVED {first} from gazebo one$", timeout=WAIT + 5)
    wait_for_line(example, rf"^REMOVED {first}$")
    wait_for_line(example, rf"^ADDED {second}$")
    wait_for_line(example, rf"^RECEIVED {second} from gazebo two$", timeout=WAIT + 5)
    wait_for_line(example, r"^DONE$")
    assert example.wait(WAIT) == 0, example.output()
    assert "Traceback" not in example.output()


def test_example_stops_on_ctrl_c_without_a_traceback(started: list[PeerProcess]) -> None:
    """Ctrl-C while it waited printed two tracebacks (rclpy's shutdown in the spin thread,
    then the KeyboardInterrupt) and no DONE."""
    example = start_process(
        [sys.executable, str(EXAMPLE), "--first", unique_name("embed_nothing"), "--timeout", "60"]
    )
    started.append(example)
    wait_for_line(example, r"^ADDED ", timeout=30)
    example.send_signal(signal.SIGINT)
    assert example.wait(WAIT) == 130, example.output()
    wait_for_line(example, r"^INTERRUPTED$")
    wait_for_line(example, r"^DONE$")
    assert "Traceback" not in example.output()


#: A program that shuts ROS down before it closes its bridge, as a Ctrl-C handler often does.
SHUTDOWN_FIRST = """
import sys, time
import rclpy
from ros_gz_bridge_py import Bridge
from ros_gz_bridge_py.config import Direction, TopicBridgeSpec

topic, gz_type = sys.argv[1], sys.argv[2]
rclpy.init()
node = rclpy.create_node("shut_down_first")
bridge = Bridge(node)
handle = bridge.add(TopicBridgeSpec(topic, topic, "std_msgs/msg/String", gz_type,
                                    Direction.GZ_TO_ROS))
channel = handle.channels[0]
while channel.stats.published < 20:
    time.sleep(0.01)
rclpy.shutdown()
while channel.dropped < 100:  # 0.5 s of the publisher's 200 Hz, every one refused by ROS
    time.sleep(0.01)
bridge.close()
print("CLOSED", flush=True)
"""


def test_ros_shut_down_before_the_bridge_closes_is_one_warning(
    started: list[PeerProcess],
) -> None:
    """A program that calls ``rclpy.shutdown()`` before ``Bridge.close()`` (what its Ctrl-C
    handler often does): every later Gazebo message was a traceback on stderr."""
    require_peer()
    topic = unique_name("embed_shutdown")
    publisher = start_peer("pub", topic, STRING, "200", "0", 'data: "tick"', "--wait", "60")
    started.append(publisher)
    wait_for_line(publisher, r"^READY$")
    program = start_process([sys.executable, "-c", SHUTDOWN_FIRST, topic, STRING])
    started.append(program)
    wait_for_line(program, r"^CLOSED$", timeout=WAIT + 10)
    assert program.wait(WAIT) == 0, program.output()
    output = program.output()
    assert "Traceback" not in output
    warnings = [line for line in output.splitlines() if "[WARN]" in line and topic in line]
    assert len(warnings) == 1, output
    assert warnings[0].endswith(
        "ROS was shut down before the bridge was closed; messages from Gazebo are dropped "
        "until it is (close the bridge before rclpy.shutdown)"
    )


@pytest.fixture(scope="module")
def bridge(ros_side: RosSide) -> Iterator[Bridge]:
    """A bridge on a node of its own in the test's context, with its own Gazebo node."""
    require_peer()
    node: Any = rclpy.create_node(
        f"embedded_bridge_{uuid.uuid4().hex[:8]}", context=ros_side.context
    )
    embedded = Bridge(node, options=BridgeOptions(heartbeat=0.2))
    yield embedded
    embedded.close()
    node.destroy_node()


def spec(topic: str, direction: Direction) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, direction)


def test_removed_gz_to_ros_bridge_leaves_nothing_behind(
    bridge: Bridge, ros_side: RosSide, gz_node: GzNode
) -> None:
    topic = unique_name("embed_gz_to_ros")
    publisher = gz_node.advertise(topic, STRING)
    try:
        handle = bridge.add(spec(topic, Direction.GZ_TO_ROS))
        assert handle in bridge.handles
        wait_until(publisher.has_connections, WAIT, "the bridge's Gazebo subscription")
        wait_until(lambda: ros_side.count_publishers(topic) == 1, WAIT, "the ROS publisher")

        bridge.remove(handle)
        assert handle not in bridge.handles
        wait_until(lambda: not publisher.has_connections(), WAIT, "the Gazebo unsubscription")
        wait_until(lambda: ros_side.count_publishers(topic) == 0, WAIT, "the ROS publisher gone")
        bridge.remove(handle)  # removing twice is harmless
    finally:
        publisher.close()


def test_removed_ros_to_gz_bridge_leaves_nothing_behind(
    bridge: Bridge, ros_side: RosSide, gz_node: GzNode
) -> None:
    topic = unique_name("embed_ros_to_gz")
    handle = bridge.add(spec(topic, Direction.ROS_TO_GZ))
    wait_gz_advertised(gz_node, topic)
    wait_until(lambda: ros_side.count_subscribers(topic) == 1, WAIT, "the ROS subscription")

    bridge.remove(handle)
    wait_until(lambda: not gz_advertised(gz_node, topic), WAIT, "the Gazebo unadvertisement")
    wait_until(lambda: ros_side.count_subscribers(topic) == 0, WAIT, "the ROS subscription gone")

    again = bridge.add(spec(topic, Direction.ROS_TO_GZ))
    wait_gz_advertised(gz_node, topic)
    bridge.remove(again)
