"""Lazy bridges: the input side exists only while the output side has a reader.

Two bridge processes, one per way of asking for laziness: the node parameter ``lazy:=true``
(applied, as in Rolling #852; Jazzy ignores it) and a YAML entry's ``lazy: true``. Each also
bridges non-lazy control topics: once a control topic is bridged, discovery has run, so a lazy
topic that is still unbridged is unbridged because it is lazy.
"""

from __future__ import annotations

import threading
from collections.abc import Iterator
from pathlib import Path
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
    holds_for,
    publish_until,
    ros_side,
    start_bridge,
    wait_gz_advertised,
)
from testing.e2e_harness import status_rows
from testing.gzpeer import Inbox, require_peer, unique_name, wait_until

__all__ = ["gz_node", "ros_side"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

HEARTBEAT_MS = 200
#: How long a lazy topic must stay unbridged: five heartbeats.
IDLE_WINDOW = 5 * HEARTBEAT_MS / 1000


def _entry(topic: str, direction: str, lazy: bool) -> str:
    return (
        f"- topic_name: {topic}\n"
        "  ros_type_name: std_msgs/msg/String\n"
        f"  gz_type_name: {STRING}\n"
        f"  direction: {direction}\n"
        f"  lazy: {str(lazy).lower()}\n"
    )


@pytest.fixture(scope="module")
def topics(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, dict[str, str]]]:
    """Per source ("parameter", "yaml"): the lazy and control topics of a running bridge."""
    require_peer()
    folder = tmp_path_factory.mktemp("lazy")
    sources: dict[str, dict[str, str]] = {}
    bridges = []
    for source in ("parameter", "yaml"):
        names = {
            key: unique_name(f"lazy_{source}_{key}")
            for key in ("gz_to_ros", "ros_to_gz", "control_gz_to_ros", "control_ros_to_gz")
        }
        entries = [
            _entry(names["control_gz_to_ros"], "GZ_TO_ROS", lazy=False),
            _entry(names["control_ros_to_gz"], "ROS_TO_GZ", lazy=False),
        ]
        args: list[str] = []
        ros_args = ["-p", f"subscription_heartbeat:={HEARTBEAT_MS}"]
        if source == "parameter":
            args = [
                f"{names['gz_to_ros']}@std_msgs/msg/String[{STRING}",
                f"{names['ros_to_gz']}@std_msgs/msg/String]{STRING}",
            ]
            ros_args += ["-p", "lazy:=true"]
        else:
            entries += [
                _entry(names["gz_to_ros"], "GZ_TO_ROS", lazy=True),
                _entry(names["ros_to_gz"], "ROS_TO_GZ", lazy=True),
            ]
        config = Path(folder / f"{source}.yaml")
        config.write_text("".join(entries))
        ros_args += ["-p", f"config_file:={config}"]
        bridges.append(start_bridge(*args, ros_args=ros_args, creating=4))
        sources[source] = names
    yield sources
    for bridge in bridges:
        bridge.stop()


@pytest.mark.parametrize("source", ["parameter", "yaml"])
def test_gz_to_ros_subscribes_to_gazebo_only_while_ros_reads(
    topics: dict[str, dict[str, str]], source: str, ros_side: RosSide, gz_node: GzNode
) -> None:
    names = topics[source]
    string_msg = message_class(STRING)
    control = gz_node.advertise(names["control_gz_to_ros"], STRING)
    publisher = gz_node.advertise(names["gz_to_ros"], STRING)
    try:
        wait_until(control.has_connections, WAIT, "the non-lazy control topic to be bridged")
        assert holds_for(lambda: not publisher.has_connections(), IDLE_WINDOW), (
            "a lazy bridge subscribed on the Gazebo side with no ROS subscriber"
        )

        inbox, subscription = ros_side.subscribe(String, names["gz_to_ros"])
        wait_until(publisher.has_connections, WAIT, "the Gazebo subscription after a ROS reader")
        publish_until(
            lambda i: publisher.publish(string_msg(data=f"lazy {i}")),
            lambda: bool(inbox.items()),
            "the ROS subscriber receives",
        )
        assert all(msg.data.startswith("lazy ") for msg, _ in inbox.items())

        ros_side.destroy(subscription)
        wait_until(lambda: not publisher.has_connections(), WAIT, "the Gazebo unsubscription")
    finally:
        control.close()
        publisher.close()


@pytest.mark.parametrize("source", ["parameter", "yaml"])
def test_ros_to_gz_subscribes_to_ros_only_while_gazebo_reads(
    topics: dict[str, dict[str, str]], source: str, ros_side: RosSide, gz_node: GzNode
) -> None:
    names = topics[source]
    topic = names["ros_to_gz"]
    wait_gz_advertised(gz_node, topic)
    wait_until(
        lambda: ros_side.count_subscribers(names["control_ros_to_gz"]) > 0,
        WAIT,
        "the non-lazy control topic to be bridged",
    )
    assert holds_for(lambda: ros_side.count_subscribers(topic) == 0, IDLE_WINDOW), (
        "a lazy bridge subscribed on the ROS side with no Gazebo subscriber"
    )

    inbox = Inbox()
    subscription = gz_node.subscribe_typed(topic, message_class(STRING), inbox, msg_type=STRING)
    publisher: Any = ros_side.run(lambda: ros_side.node.create_publisher(String, topic, 10))
    try:
        wait_until(lambda: ros_side.count_subscribers(topic) > 0, WAIT, "the ROS subscription")
        publish_until(
            lambda i: publisher.publish(String(data=f"to gz {i}")),
            lambda: bool(inbox.items()),
            "the Gazebo subscriber receives",
        )
        assert all(msg.data.startswith("to gz ") for msg, _ in inbox.items())
    finally:
        subscription.close()
    wait_until(lambda: ros_side.count_subscribers(topic) == 0, WAIT, "the ROS unsubscription")
    ros_side.destroy(publisher)


def test_a_lazy_channel_counts_what_it_carried_until_it_closed(
    ros_side: RosSide, gz_node: GzNode
) -> None:
    """The counts of a channel's last moments before its input closes (the native loop reports
    them every quarter second) are the channel's: OUT is at least what its reader got (the
    native path lost them: 96 counted for 101 delivered)."""
    require_peer()
    topic = unique_name("lazy_counts")
    bridge = start_bridge(
        f"{topic}@std_msgs/msg/String[{STRING}",
        ros_args=["-p", "lazy:=true", "-p", f"subscription_heartbeat:={HEARTBEAT_MS}"],
        creating=1,
    )
    string_msg = message_class(STRING)
    publisher = gz_node.advertise(topic, STRING)
    stop = threading.Event()
    sent = [0]

    def publish() -> None:
        while not stop.wait(0.005):
            publisher.publish(string_msg(data="counted"))
            sent[0] += 1

    sender = threading.Thread(target=publish, daemon=True)
    try:
        inbox, subscription = ros_side.subscribe(String, topic)
        wait_until(publisher.has_connections, WAIT, "the Gazebo subscription after a ROS reader")
        sender.start()
        inbox.wait_for_count(100, WAIT)
        ros_side.destroy(subscription)  # the reader goes while messages flow
        wait_until(lambda: not publisher.has_connections(), WAIT, "the Gazebo unsubscription")
        stop.set()
        sender.join()
        delivered = len(inbox.items())
        (row,) = [r.split() for r in status_rows(bridge, [topic]) if r.split()[1:2] == ["GZ->ROS"]]
        received, published = int(row[5]), int(row[6])  # IN, OUT
        assert sent[0] >= received >= published >= delivered, (sent, row, delivered)
    finally:
        stop.set()
        publisher.close()
        bridge.stop()
