"""A native ROS -> Gazebo loop that has been quiet learns a new Gazebo subscriber at once
(docs/native.md §7).

An idle loop returns to Python only every ``COUNT_EVERY`` seconds; what it reads there that
changes (the spellings Gazebo subscribers take, the bridge's own publishers) is pushed to it.
A Fortress subscriber (the C++ peer, ``ignition.msgs`` spelling) that appears while the loop is
quiet must get a single message published a moment after it is discovered: without the push the
loop would still send no spelling, and the message would be lost. Three subscribers in turn, each
at another point of a quiet run.
"""

from __future__ import annotations

import time

import pytest
from std_msgs.msg import String

from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.loop import COUNT_EVERY
from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_node,
    ros_side,
    start_bridge,
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

#: After the test's own node saw the subscriber, before the single message: the bridge hears
#: the same announcement, and the subscriber connects to the bridge's socket, in milliseconds.
MARGIN = 0.3


def subscribed(gz_node: GzNode, topic: str) -> bool:
    return any(e.role == "subscriber" and e.topic == topic for e in gz_node.graph())


def test_a_quiet_loop_sends_to_a_fortress_subscriber_that_just_appeared(
    gz_node: GzNode, ros_side: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    if extension() is None:
        pytest.skip("the native extension is not built here")
    topic = unique_name("quiet_loop")
    started.append(start_bridge(f"{topic}@std_msgs/msg/String]{STRING}", creating=1))
    publisher = ros_side.run(lambda: ros_side.node.create_publisher(String, topic, 10))
    wait_until(lambda: ros_side.count_subscribers(topic) >= 1, WAIT, "the bridge's subscription")
    time.sleep(1.0)  # no message yet: the loop's runs are quiet ones now
    for attempt in range(3):
        echo = start_peer("echo", topic, "ignition.msgs.StringMsg", str(WAIT), "--count", "1")
        started.append(echo)
        wait_for_line(echo, "^READY", timeout=WAIT)
        wait_until(lambda: subscribed(gz_node, topic), WAIT, "the Fortress subscriber")
        time.sleep(MARGIN)
        message = String(data=f"single {attempt}")
        ros_side.run(lambda: publisher.publish(message))  # noqa: B023 - run calls it at once
        wait_for_line(echo, f'^MSG ignition.msgs.StringMsg data: "single {attempt}"', WAIT)
        echo.stop()
        wait_until(lambda: not subscribed(gz_node, topic), WAIT, "the subscriber gone")
        time.sleep(COUNT_EVERY * (attempt + 1) / 4)  # another point of a quiet run
