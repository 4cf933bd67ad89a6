"""The QoS of the bridge's ROS endpoints, as the channels choose it and as the graph shows it.

C++ defaults (reliable, volatile, keep-last 10), ``qos_profile``, ``publisher_queue`` and
``subscriber_queue``, ``/tf_static`` transient-local towards ROS, and ``qos_overrides``
parameters (read by rclpy from the bridge node's parameters when an endpoint is created).
"""

from __future__ import annotations

from typing import Any

import pytest
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.msgs import message_class
from tests.core.harness import (
    Rig,
    RosWorld,
    gz_to_ros,
    publish_until,
    ros_to_gz,
    unique,
    wait_until,
)

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING = "gz.msgs.StringMsg"
RELIABLE, BEST_EFFORT = ReliabilityPolicy.RELIABLE, ReliabilityPolicy.BEST_EFFORT
VOLATILE, TRANSIENT_LOCAL = DurabilityPolicy.VOLATILE, DurabilityPolicy.TRANSIENT_LOCAL


def string_spec(topic: str, **fields: Any) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, **fields)


def policies(profile: QoSProfile) -> tuple[Any, Any, Any, int]:
    return (profile.reliability, profile.durability, profile.history, profile.depth)


def shown(infos: list[Any]) -> tuple[Any, Any]:
    """Reliability and durability of the one endpoint the graph shows (it tells no depth)."""
    (info,) = infos
    return (info.qos_profile.reliability, info.qos_profile.durability)


def test_default_is_reliable_volatile_depth_10_both_ways(rig: Rig, world: RosWorld) -> None:
    topic = unique("qos_default")
    handle = rig.add(string_spec(topic, direction=Direction.BIDIRECTIONAL))
    expected = (RELIABLE, VOLATILE, HistoryPolicy.KEEP_LAST, 10)
    assert policies(gz_to_ros(handle).qos) == expected
    assert policies(ros_to_gz(handle).qos) == expected
    wait_until(lambda: len(world.publishers(topic)) == 1, "the bridge's publisher")
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the bridge's subscription")
    assert shown(world.publishers(topic)) == (RELIABLE, VOLATILE)
    assert shown(world.subscribers(topic)) == (RELIABLE, VOLATILE)


@pytest.mark.parametrize(
    ("profile", "expected"),
    [
        ("SENSOR_DATA", (BEST_EFFORT, VOLATILE, HistoryPolicy.KEEP_LAST, 5)),
        ("CLOCK", (BEST_EFFORT, VOLATILE, HistoryPolicy.KEEP_LAST, 1)),
        ("ROSOUT", (RELIABLE, TRANSIENT_LOCAL, HistoryPolicy.KEEP_LAST, 1000)),
    ],
)
def test_a_named_profile_sets_both_endpoints(
    rig: Rig, world: RosWorld, profile: str, expected: tuple[Any, ...]
) -> None:
    topic = unique("qos_profile")
    handle = rig.add(string_spec(topic, qos_profile=profile))
    assert policies(gz_to_ros(handle).qos) == expected
    assert policies(ros_to_gz(handle).qos) == expected
    wait_until(lambda: len(world.publishers(topic)) == 1, "the bridge's publisher")
    assert shown(world.publishers(topic)) == expected[:2]


def test_queues_set_the_depth_of_their_own_side(rig: Rig) -> None:
    plain = rig.add(string_spec(unique("qos_queues"), publisher_queue=3, subscriber_queue=7))
    assert policies(gz_to_ros(plain).qos) == (RELIABLE, VOLATILE, HistoryPolicy.KEEP_LAST, 3)
    assert policies(ros_to_gz(plain).qos) == (RELIABLE, VOLATILE, HistoryPolicy.KEEP_LAST, 7)
    profiled = rig.add(
        string_spec(unique("qos_queues"), qos_profile="SENSOR_DATA", publisher_queue=2)
    )
    assert policies(gz_to_ros(profiled).qos) == (BEST_EFFORT, VOLATILE, HistoryPolicy.KEEP_LAST, 2)
    assert policies(ros_to_gz(profiled).qos) == (BEST_EFFORT, VOLATILE, HistoryPolicy.KEEP_LAST, 5)


def test_tf_static_is_latched_towards_ros(make_rig: Any, world: RosWorld) -> None:
    """Only the Gazebo->ROS publisher, only without a profile; a late reader gets the last."""
    # A bridge of its own: rclpy keeps one set of qos_overrides parameters per node and topic,
    # and a second publisher of /tf_static on the same node would take the first one's QoS.
    profiled = make_rig().add(
        TopicBridgeSpec("/tf_static", "/core_tf_static_gz", "tf2_msgs/msg/TFMessage",
                        "gz.msgs.Pose_V", Direction.GZ_TO_ROS, qos_profile="SENSOR_DATA")
    )  # fmt: skip
    assert gz_to_ros(profiled).qos.durability == VOLATILE
    rig: Rig = make_rig()
    handle = rig.add(
        TopicBridgeSpec("/tf_static", "/tf_static", "tf2_msgs/msg/TFMessage", "gz.msgs.Pose_V")
    )
    assert gz_to_ros(handle).qos.durability == TRANSIENT_LOCAL
    assert ros_to_gz(handle).qos.durability == VOLATILE

    latched = QoSProfile(depth=10, reliability=RELIABLE, durability=TRANSIENT_LOCAL)
    publisher = rig.gazebo().advertise("/tf_static", "gz.msgs.Pose_V")
    early, _ = world.subscribe(TFMessage, "/tf_static", latched)

    def pose_v(x: float) -> Any:
        message = message_class("gz.msgs.Pose_V")()
        pose = message.pose.add()
        pose.header.data.add(key="child_frame_id", value=["static_child"])
        pose.position.x = x
        pose.orientation.w = 1.0
        return message

    publish_until(lambda i: publisher.publish(pose_v(i)), lambda: bool(early.messages()),
                  "the first /tf_static message")  # fmt: skip
    publisher.publish(pose_v(1000.0))
    early.wait_for(lambda got: got[-1].transforms[0].transform.translation.x == 1000.0, "the last")
    late, _ = world.subscribe(TFMessage, "/tf_static", latched)
    got = late.wait_for(
        lambda got: any(m.transforms[0].transform.translation.x == 1000.0 for m in got),
        "the stored /tf_static for a late reader",
    )
    assert got[-1].transforms[0].child_frame_id == "static_child"


def test_qos_overrides_parameters_apply_per_topic(make_rig: Any, world: RosWorld) -> None:
    to_ros, to_gz, untouched = unique("ovr_pub"), unique("ovr_sub"), unique("ovr_none")
    rig: Rig = make_rig(
        node_options={
            "parameter_overrides": [
                Parameter(f"qos_overrides.{to_ros}.publisher.reliability", value="best_effort"),
                Parameter(f"qos_overrides.{to_gz}.subscription.reliability", value="best_effort"),
            ]
        }
    )
    rig.add(string_spec(to_ros, direction=Direction.GZ_TO_ROS))
    rig.add(string_spec(to_gz, direction=Direction.ROS_TO_GZ))
    rig.add(string_spec(untouched, direction=Direction.GZ_TO_ROS))
    wait_until(lambda: len(world.publishers(to_ros)) == 1, "the overridden publisher")
    wait_until(lambda: len(world.subscribers(to_gz)) == 1, "the overridden subscription")
    wait_until(lambda: len(world.publishers(untouched)) == 1, "the other publisher")
    assert shown(world.publishers(to_ros)) == (BEST_EFFORT, VOLATILE)
    assert shown(world.subscribers(to_gz)) == (BEST_EFFORT, VOLATILE)
    assert shown(world.publishers(untouched)) == (RELIABLE, VOLATILE)


def test_a_subscription_override_reaches_a_bidirectional_entry(
    make_rig: Any, world: RosWorld
) -> None:
    topic = unique("ovr_bidi")
    override = Parameter(f"qos_overrides.{topic}.subscription.reliability", value="best_effort")
    rig: Rig = make_rig(node_options={"parameter_overrides": [override]})
    assert ros_to_gz(rig.add(string_spec(topic))).loop_guard  # so it is on the side node
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the bridge's subscription")
    assert shown(world.subscribers(topic)) == (BEST_EFFORT, VOLATILE)
    # Declared where the user wrote it, as for every other entry.
    parameter = f"qos_overrides.{topic}.subscription.reliability"
    assert rig.node.get_parameter(parameter).value == "best_effort"
