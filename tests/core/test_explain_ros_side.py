"""Explanations of the ROS side in one process: ROS endpoints of another type or with a QoS
that cannot match, and how often the explainer asks the graph (``judge.py`` moves the clock).
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Iterator
from typing import Any

import pytest
import rclpy
from rclpy.context import Context
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.utilities import try_shutdown
from std_msgs.msg import Int32, String

from ros_gz_bridge_py.config import Direction
from ros_gz_bridge_py.core.channel import Channel
from ros_gz_bridge_py.core.explain import EXPLAIN_PERIOD, ROS_ENDPOINTS_REFRESH, Explainer
from ros_gz_bridge_py.core.ros_endpoints import qos_errors, qos_fixes
from tests.core.harness import (
    Rig,
    RosWorld,
    gz_to_ros,
    unique,
    wait_until,
)
from tests.core.judge import STRING, Judge, string_spec, texts

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process


@pytest.fixture
def other_process() -> Iterator[Any]:
    """A node of another rclpy context (another DDS participant), as another ROS process
    would be: one context cannot hold two types on one topic."""
    context = Context()
    rclpy.init(context=context)
    node = rclpy.create_node(f"core_other_{uuid.uuid4().hex[:8]}", context=context)
    yield node
    node.destroy_node()
    try_shutdown(context=context)


def test_a_ros_reader_of_another_type_is_explained(
    rig: Rig, world: RosWorld, other_process: Any
) -> None:
    topic = unique("ros_type")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    rig.gazebo().advertise(topic, STRING)
    other_process.create_subscription(Int32, topic, lambda _m: None, 10)
    wait_until(
        lambda: any(i.node_name == other_process.get_name() for i in world.subscribers(topic)),
        "the other process's subscriber, and its node, in the graph",
    )
    Judge(rig).evaluate()
    assert texts(channel) == [
        f"the ROS subscriber /{other_process.get_name()} of {topic} uses std_msgs/msg/Int32, "
        "but the bridge is configured with std_msgs/msg/String; std_msgs/msg/Int32 pairs with "
        "gz.msgs.Int32: set the ROS and Gazebo types to such a pair; or have "
        f"/{other_process.get_name()} subscribe to std_msgs/msg/String"
    ]


@pytest.mark.parametrize(
    ("profile", "reader", "told"),
    [("CLOCK", QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE),
      ("Best effort publisher and reliable subscription", "publisher.reliability:=reliable")),
     (None, QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL),
      ("Volatile publisher and transient local subscription",
       "publisher.durability:=transient_local"))],
)  # fmt: skip
def test_a_ros_reader_with_incompatible_qos_is_told_the_parameter_that_matches_it(
    world: RosWorld,
    make_rig: Callable[..., Rig],
    profile: str | None,
    reader: QoSProfile,
    told: tuple[str, str],
) -> None:
    """``told``: rcl's reason, and the override the fix names."""
    reason, fix = told
    topic = unique("ros_qos")
    world.subscribe(String, topic, reader)
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the reader in the graph")

    def texts_of(node_options: dict[str, Any] | None) -> list[str]:
        rig = make_rig(node_options=node_options)
        channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS, qos_profile=profile)))
        rig.gazebo().advertise(topic, STRING)
        Judge(rig).evaluate()
        return texts(channel)

    assert texts_of(None) == [
        f"the ROS subscriber /{world.node.get_name()} of {topic} cannot match the bridge's "
        f"QoS: {reason}; run the bridge with --ros-args -p qos_overrides.{topic}.{fix} (or set "
        "the entry's qos_profile to match)"
    ]
    # The parameter named is the fix: given to the bridge node, the reader matches.
    name, value = fix.split(":=")
    given = {"parameter_overrides": [Parameter(f"qos_overrides.{topic}.{name}", value=value)]}
    assert texts_of(given) == []


def test_rcl_qos_reasons_become_a_clause_of_the_explanation() -> None:
    """rcl's markup ("ERROR: ...;", warnings beside) is not passed on as it is."""
    reason = (
        "ERROR: Best effort publisher and reliable subscription;"
        "WARNING: Publisher deadline is default;ERROR: Volatile publisher and transient local "
        "subscription;"
    )
    assert qos_errors(reason) == (
        "Best effort publisher and reliable subscription, "
        "Volatile publisher and transient local subscription"
    )


def test_qos_fixes_name_the_overrides_of_the_bridges_own_endpoint() -> None:
    best_effort = QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT)
    reliable = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    # ROS->Gazebo: a best-effort sensor publisher, the bridge's reliable subscription.
    assert qos_fixes(False, best_effort, reliable) == ("subscription.reliability:=best_effort",)
    # Gazebo->ROS: the bridge publishes best effort and volatile to a reliable latched reader.
    assert qos_fixes(True, best_effort, latched) == (
        "publisher.reliability:=reliable",
        "publisher.durability:=transient_local",
    )
    # A subscription's durability has no override: nothing to propose there.
    assert qos_fixes(False, reliable, latched) == ()


def _read_by_another_type(
    rig: Rig, world: RosWorld, other_process: Any, monkeypatch: pytest.MonkeyPatch, label: str
) -> tuple[str, Channel, list[str]]:
    """A Gazebo -> ROS channel whose topic another process's node reads as another type, and
    the topics the bridge's node is asked the subscribers of from now on."""
    topic = unique(label)
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    rig.gazebo().advertise(topic, STRING)
    other_process.create_subscription(Int32, topic, lambda _m: None, 10)
    wait_until(lambda: len(world.subscribers(topic)) == 1, "the other type's reader in the graph")
    asked: list[str] = []
    ask = rig.node.get_subscriptions_info_by_topic

    def spy(name: str) -> Any:
        asked.append(name)
        return ask(name)

    monkeypatch.setattr(rig.node, "get_subscriptions_info_by_topic", spy)
    return topic, channel, asked


def test_a_graph_of_the_bridges_nodes_alone_asks_no_topics_endpoints(
    rig: Rig, world: RosWorld, other_process: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    topic, channel, asked = _read_by_another_type(rig, world, other_process, monkeypatch, "alone")
    judge = Judge(rig)
    judge.evaluate()  # another process's node is in the graph: its reader is found
    assert asked == [topic]
    assert [f.key.split(":")[0] for f in channel.findings] == ["ros-type"]
    # The same graph, every node in it taken for the bridge's: nothing is asked, nothing found.
    every = set(rig.node.get_node_names_and_namespaces())
    alone = Explainer(rig.gz, rig.bridge.registry, every, judge.logged.append, now=lambda: 0.0)
    rig.world.run(lambda: alone.evaluate(rig.bridge.channels))
    assert asked == [topic]
    assert channel.findings == []


def test_ros_endpoints_are_asked_again_only_when_the_graph_changes_or_they_are_old(
    rig: Rig, world: RosWorld, other_process: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A channel's ROS endpoints are reused while the graph's nodes and the topic's count of
    them stay the same; a reader that comes has them asked at the next pass, and so do
    ROS_ENDPOINTS_REFRESH seconds, whatever the graph."""
    topic, channel, asked = _read_by_another_type(rig, world, other_process, monkeypatch, "asked")
    judge = Judge(rig)
    judge.evaluate()
    judge.evaluate(EXPLAIN_PERIOD)
    assert asked == [topic]
    assert [f.key.split(":")[0] for f in channel.findings] == ["ros-type"]
    world.subscribe(String, topic, QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE))
    wait_until(lambda: len(world.subscribers(topic)) == 2, "the second reader in the graph")
    judge.evaluate(EXPLAIN_PERIOD)
    assert asked == [topic, topic]
    judge.evaluate(EXPLAIN_PERIOD)
    assert asked == [topic, topic]
    judge.evaluate(ROS_ENDPOINTS_REFRESH)
    assert asked == [topic, topic, topic]
