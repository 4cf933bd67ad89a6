"""QoS, header rewriting and names, as another ROS node and a Gazebo node see them.

Two bridge processes: one for QoS and headers (``/tf_static``, a ``qos_overrides`` parameter,
``override_frame_id``, a YAML ``frame_id``, ``override_timestamps_with_wall_time``), one for
names (``-r __ns:=/robot1`` with ``expand_gz_topic_names``, and a ``-r /a:=/b`` remapping).
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from geometry_msgs.msg import PoseStamped
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.config.model import MAX_QUEUE_DEPTH
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.transport import GzNode
from testing.behaviour_harness import (
    STRING,
    WAIT,
    RosSide,
    gz_advertised,
    gz_node,
    publish_until,
    relative,
    ros_side,
    start_bridge,
    started,
    wait_gz_advertised,
)
from testing.gzpeer import PeerProcess, require_peer, unique_name, wait_for_line, wait_until

__all__ = ["gz_node", "ros_side", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

POSE = "ignition.msgs.Pose"
POSE_V = "ignition.msgs.Pose_V"
OVERRIDE_FRAME = "override_frame"
YAML_FRAME = "yaml_frame"
NAMESPACE = "/robot1"
#: A recognisable last /tf_static message (its translation x).
LAST_X = 1000.0


@pytest.fixture(scope="module")
def qos_topics(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, str]]:
    require_peer()
    keys = ("best_effort", "reliable", "frame", "deep")
    topics = {key: unique_name(f"qos_{key}") for key in keys}
    topics["yaml_frame"] = unique_name("qos_yaml_frame")
    config = Path(tmp_path_factory.mktemp("qos") / "frames.yaml")
    config.write_text(
        f"- topic_name: {topics['yaml_frame']}\n"
        "  ros_type_name: geometry_msgs/msg/PoseStamped\n"
        f"  gz_type_name: {POSE}\n"
        "  direction: GZ_TO_ROS\n"
        f"  frame_id: {YAML_FRAME}\n"
    )
    bridge = start_bridge(
        f"/tf_static@tf2_msgs/msg/TFMessage[{POSE_V}",
        f"{topics['best_effort']}@std_msgs/msg/String[{STRING}",
        f"{topics['reliable']}@std_msgs/msg/String[{STRING}",
        f"{topics['frame']}@geometry_msgs/msg/PoseStamped[{POSE}",
        f"{topics['deep']}@std_msgs/msg/String[{STRING}",
        ros_args=[
            "-p", f"qos_overrides.{topics['best_effort']}.publisher.reliability:=best_effort",
            "-p", f"qos_overrides.{topics['deep']}.publisher.depth:={MAX_QUEUE_DEPTH + 1}",
            "-p", f"override_frame_id:={OVERRIDE_FRAME}",
            "-p", "override_timestamps_with_wall_time:=true",
            "-p", f"config_file:={config}",
        ],
        creating=6,
    )  # fmt: skip
    yield topics
    bridge.stop()


@pytest.fixture(scope="module")
def name_topics(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, str]]:
    require_peer()
    topics = {key: relative(unique_name(f"names_{key}")) for key in ("cli", "yaml_ros", "yaml_gz")}
    topics |= {key: unique_name(f"names_{key}") for key in ("remap_from", "remap_to")}
    config = Path(tmp_path_factory.mktemp("names") / "names.yaml")
    config.write_text(
        f"- ros_topic_name: {topics['yaml_ros']}\n"
        f"  gz_topic_name: {topics['yaml_gz']}\n"
        "  ros_type_name: std_msgs/msg/String\n"
        f"  gz_type_name: {STRING}\n"
        "  direction: ROS_TO_GZ\n"
    )
    bridge = start_bridge(
        f"{topics['cli']}@std_msgs/msg/String]{STRING}",
        f"{topics['remap_from']}@std_msgs/msg/String]{STRING}",
        ros_args=[
            "-r", f"__ns:={NAMESPACE}",
            "-r", f"{topics['remap_from']}:={topics['remap_to']}",
            "-p", "expand_gz_topic_names:=true",
            "-p", f"config_file:={config}",
        ],
        creating=3,
    )  # fmt: skip
    yield topics
    bridge.stop()


def pose_v(x: float) -> Any:
    message = message_class(POSE_V)()
    pose = message.pose.add()
    pose.header.data.add(key="child_frame_id", value=["static_child"])
    pose.position.x = x
    pose.orientation.w = 1.0
    return message


def transient_local() -> QoSProfile:
    return QoSProfile(
        depth=10,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def endpoint_qos(ros_side: RosSide, topic: str) -> Any:
    """The QoS of the bridge's publisher on ``topic``, the only one (waiting until known)."""

    def bridge_publishers() -> list[Any]:
        infos = ros_side.run(lambda: ros_side.node.get_publishers_info_by_topic(topic))
        return [info for info in infos if info.node_name == "ros_gz_bridge"]

    wait_until(lambda: bool(bridge_publishers()), WAIT, f"the bridge's publisher of {topic}")
    assert ros_side.count_publishers(topic) == 1
    return bridge_publishers()[0].qos_profile


def test_tf_static_is_latched_for_late_subscribers(
    qos_topics: dict[str, str], ros_side: RosSide, gz_node: GzNode
) -> None:
    assert endpoint_qos(ros_side, "/tf_static").durability == DurabilityPolicy.TRANSIENT_LOCAL
    publisher = gz_node.advertise("/tf_static", POSE_V)
    early, early_subscription = ros_side.subscribe(TFMessage, "/tf_static", transient_local())
    try:
        wait_until(publisher.has_connections, WAIT, "the bridge's /tf_static subscription")
        publish_until(lambda i: publisher.publish(pose_v(float(i))), lambda: bool(early.items()),
                      "the first /tf_static message arrives")  # fmt: skip
        publisher.publish(pose_v(LAST_X))
        early.wait_for(
            lambda items: items[-1][0].transforms[0].transform.translation.x == LAST_X,
            WAIT,
            "the last /tf_static message",
        )

        late, late_subscription = ros_side.subscribe(TFMessage, "/tf_static", transient_local())
        received = late.wait_for_count(1, WAIT)
        time.sleep(0.5)  # the rest of the stored history, if any
        received = late.items()
        assert received[-1][0].transforms[0].transform.translation.x == LAST_X
        assert received[-1][0].transforms[0].child_frame_id == "static_child"
        ros_side.destroy(late_subscription)
    finally:
        ros_side.destroy(early_subscription)
        publisher.close()


def test_qos_override_parameter_sets_the_publisher_reliability(
    qos_topics: dict[str, str], ros_side: RosSide
) -> None:
    best_effort = endpoint_qos(ros_side, qos_topics["best_effort"])
    assert best_effort.reliability == ReliabilityPolicy.BEST_EFFORT
    reliable = endpoint_qos(ros_side, qos_topics["reliable"])
    assert reliable.reliability == ReliabilityPolicy.RELIABLE
    assert reliable.durability == DurabilityPolicy.VOLATILE


def test_a_publisher_depth_deeper_than_the_bridge_queue_still_carries(
    qos_topics: dict[str, str], ros_side: RosSide, gz_node: GzNode
) -> None:
    """The ROS history takes the override; the bridge's own queue stops at MAX_QUEUE_DEPTH
    (the channel was refused with the native queue's 'capacity out of range' before)."""
    topic = qos_topics["deep"]
    publisher = gz_node.advertise(topic, STRING)
    inbox, subscription = ros_side.subscribe(String, topic)
    try:
        wait_until(publisher.has_connections, WAIT, f"the bridge's subscription to {topic}")
        publish_until(lambda _: publisher.publish(message_class(STRING)(data="deep")),
                      lambda: bool(inbox.items()), f"{topic} arrives")  # fmt: skip
        assert inbox.items()[0][0].data == "deep"
    finally:
        ros_side.destroy(subscription)
        publisher.close()


@pytest.mark.parametrize(("side", "symbol"), [("publisher", "["), ("subscription", "]")])
def test_a_negative_override_depth_is_one_error_naming_it(
    side: str, symbol: str, started: list[PeerProcess]
) -> None:
    """It reached the middleware: 'failed to set history depth since the requested queue
    size exceeds the DDS type', after an rcutils 'error state is being overwritten' block."""
    topic = unique_name(f"qos_negative_{side}")
    bridge = start_bridge(
        f"{topic}@std_msgs/msg/String{symbol}{STRING}",
        ros_args=["-p", f"qos_overrides.{topic}.{side}.depth:=-3"],
    )
    started.append(bridge)
    error = wait_for_line(bridge, r"\[ERROR\].*Failed to create a bridge", timeout=30).string
    assert error.endswith(
        f"Provided QoS overrides for {side} `{topic}` with id `None`, are not valid: depth -3 "
        "is negative; give the depth of history to keep (0: the middleware's default)"
    )
    wait_for_line(bridge, r"No bridges are running", timeout=WAIT)
    assert "rcutils" not in bridge.output()


@pytest.mark.parametrize(("key", "frame"), [("frame", OVERRIDE_FRAME), ("yaml_frame", YAML_FRAME)])
def test_frame_id_and_wall_time_stamps_are_rewritten(
    qos_topics: dict[str, str], key: str, frame: str, ros_side: RosSide, gz_node: GzNode
) -> None:
    topic = qos_topics[key]
    message = message_class(POSE)()
    message.header.stamp.sec = 5
    message.header.data.add(key="frame_id", value=["gz_frame"])
    message.position.x = 2.5
    publisher = gz_node.advertise(topic, POSE)
    inbox, subscription = ros_side.subscribe(PoseStamped, topic)
    try:
        wait_until(publisher.has_connections, WAIT, f"the bridge's subscription to {topic}")
        publish_until(lambda _: publisher.publish(message), lambda: bool(inbox.items()),
                      f"{topic} arrives")  # fmt: skip
        received = inbox.items()[0][0]
        assert received.pose.position.x == 2.5
        assert received.header.frame_id == frame
        stamp = received.header.stamp.sec + received.header.stamp.nanosec / 1e9
        assert abs(stamp - time.time()) < 60, "the stamp is not wall time (Gazebo said 5 s)"
    finally:
        ros_side.destroy(subscription)
        publisher.close()


def test_expand_gz_topic_names_prefixes_yaml_and_command_line_entries(
    name_topics: dict[str, str], ros_side: RosSide, gz_node: GzNode
) -> None:
    """C++ expands YAML entries only (ros_gz issue 702); ours the command line's too."""
    yaml_gz = f"{NAMESPACE}/{name_topics['yaml_gz']}"
    wait_gz_advertised(gz_node, yaml_gz)
    assert not gz_advertised(gz_node, f"/{name_topics['yaml_gz']}")
    wait_until(
        lambda: ros_side.count_subscribers(f"{NAMESPACE}/{name_topics['yaml_ros']}") == 1,
        WAIT,
        "the YAML entry's ROS subscription in the namespace",
    )

    cli = name_topics["cli"]
    wait_gz_advertised(gz_node, f"{NAMESPACE}/{cli}")
    assert not gz_advertised(gz_node, f"/{cli}")
    wait_until(
        lambda: ros_side.count_subscribers(f"{NAMESPACE}/{cli}") == 1,
        WAIT,
        "the CLI entry's ROS subscription in the namespace",
    )


def test_remapping_renames_the_ros_side_only(
    name_topics: dict[str, str], ros_side: RosSide, gz_node: GzNode
) -> None:
    wait_gz_advertised(gz_node, name_topics["remap_from"])
    assert not gz_advertised(gz_node, name_topics["remap_to"])
    wait_until(
        lambda: ros_side.count_subscribers(name_topics["remap_to"]) == 1,
        WAIT,
        "the remapped ROS subscription",
    )
    assert ros_side.count_subscribers(name_topics["remap_from"]) == 0
