"""Flow states and explanations in one process: ``Explainer.evaluate`` on real channels.

The bridge's own explain timer is off (the test options); each test makes an
:class:`~ros_gz_bridge_py.core.explain.Explainer` with a clock it moves, so warm-up,
confirmation and "logged once" are checked at exact moments instead of waited for. The
Gazebo side is memory nodes (``observe`` shows their endpoints, every partition); the ROS
side is the graph of this process's contexts.
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

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec
from ros_gz_bridge_py.core.channel import Channel
from ros_gz_bridge_py.core.diagnosis import Flow
from ros_gz_bridge_py.core.explain import (
    CONFIRM_AFTER,
    EXPLAIN_PERIOD,
    RELOG_AFTER,
    ROS_ENDPOINTS_REFRESH,
    WARM_UP,
    Explainer,
    qos_errors,
    qos_fixes,
)
from ros_gz_bridge_py.core.status import OK, WARN, StatusTracker
from ros_gz_bridge_py.msgs import message_class
from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.ros.side_node import side_node_name
from tests.core.harness import (
    Inbox,
    Rig,
    RosWorld,
    gz_to_ros,
    publish_until,
    ros_to_gz,
    settled,
    unique,
    wait_until,
)

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING = "gz.msgs.StringMsg"
GzString = message_class(STRING)


class Judge:
    """An explainer of one rig's channels, with its own clock and log."""

    def __init__(self, rig: Rig) -> None:
        self.rig = rig
        self.now = 500.0
        self.logged: list[str] = []  # warnings
        self.noted: list[str] = []  # sides not there yet
        node = rig.node
        own = {
            (node.get_name(), node.get_namespace()),
            (side_node_name(node), node.get_namespace()),
        }
        self.explainer = Explainer(
            rig.gz,
            rig.bridge.registry,
            own,
            self.logged.append,
            now=lambda: self.now,
            note=self.noted.append,
        )

    def evaluate(self, after: float = 0.0) -> None:
        """Move the clock by ``after`` seconds and evaluate every channel of the bridge."""
        self.now += after
        channels = self.rig.bridge.channels
        self.rig.world.run(lambda: self.explainer.evaluate(channels))

    def until_confirmed(self) -> None:
        """Evaluate now, past the warm-up and past the confirmation: a cause that lasted
        through all three is logged by the last."""
        self.evaluate()
        self.evaluate(WARM_UP)
        self.evaluate(CONFIRM_AFTER)


def spec(
    topic: str, direction: Direction, ros_type: str, gz_type: str, **fields: Any
) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, ros_type, gz_type, direction, **fields)


def string_spec(topic: str, direction: Direction, **fields: Any) -> TopicBridgeSpec:
    return spec(topic, direction, "std_msgs/msg/String", STRING, **fields)


def texts(channel: Channel) -> list[str]:
    return [finding.text for finding in channel.findings]


def flow_of(channel: Channel) -> Flow | None:
    """The channel's flow as the last evaluation set it."""
    return channel.flow


@pytest.mark.parametrize(
    ("native", "published", "proposed"),
    [(Spelling.GZ, "gz.msgs.Pose", "gz.msgs.Pose"),
     (Spelling.IGNITION, "ignition.msgs.Pose", "gz.msgs.Pose")],
)  # fmt: skip
def test_a_gazebo_publisher_of_another_type_is_explained_once(
    rig: Rig, native: Spelling, published: str, proposed: str
) -> None:
    topic = unique("odom")
    channel = gz_to_ros(
        rig.add(spec(topic, Direction.GZ_TO_ROS, "nav_msgs/msg/Odometry", "gz.msgs.Odometry"))
    )
    gazebo = rig.gazebo(native=native)
    gazebo.advertise(topic, published)
    judge = Judge(rig)

    judge.evaluate()
    where = f"process {gazebo.process_uuid[:8]} at memory://{gazebo.process_uuid}"
    assert flow_of(channel) is Flow.WAITING_GAZEBO
    (text,) = texts(channel)
    assert text.startswith(
        f"the Gazebo publisher of {topic} ({where}) publishes {published}, but the bridge is "
        f"configured with gz.msgs.Odometry; {proposed} pairs with geometry_msgs/msg/Pose, "
    )
    assert text.endswith(f": set the Gazebo type to {proposed} and the ROS type to one of those")
    assert judge.logged == []  # discovery is given its warm-up before anything is said

    judge.evaluate(WARM_UP)
    assert judge.logged == []  # seen once after the warm-up: not confirmed yet
    judge.evaluate(CONFIRM_AFTER)
    assert judge.logged == [f"{channel.describe()}: waiting for Gazebo: {text}"]
    judge.evaluate(2.0)
    judge.evaluate(2.0)
    assert len(judge.logged) == 1  # once per cause

    (status,) = StatusTracker(rig.bridge).snapshot()
    assert (status.flow, status.why, status.level) == ("waiting for Gazebo", text, WARN)
    assert status.message() == f"waiting for Gazebo: {text}"


def test_a_fix_in_the_configuration_spelling_is_proposed(rig: Rig) -> None:
    """The ROS type pairs with what Gazebo publishes: only the Gazebo type needs fixing, in
    the spelling the configuration writes (either works)."""
    topic = unique("odom_ign")
    configured = "ignition.msgs.OdometryWithCovariance"
    channel = gz_to_ros(
        rig.add(spec(topic, Direction.GZ_TO_ROS, "nav_msgs/msg/Odometry", configured))
    )
    rig.gazebo(native=Spelling.GZ).advertise(topic, "gz.msgs.Odometry")
    Judge(rig).evaluate()
    (text,) = texts(channel)
    assert text.endswith(
        f"publishes gz.msgs.Odometry, but the bridge is configured with {configured}; "
        "set the Gazebo type (gz_type_name) to ignition.msgs.Odometry"
    )


def test_flowing_then_stalled(rig: Rig, world: RosWorld) -> None:
    topic = unique("flow")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    judge = Judge(rig)
    judge.evaluate()
    assert (flow_of(channel), channel.findings) == (Flow.STALLED, [])  # a publisher, no message yet

    inbox, _ = world.subscribe(String, topic)
    sent = publish_until(
        lambda i: publisher.publish(GzString(data=str(i))),
        lambda: bool(inbox.messages()),
        "a message in ROS",
    )
    settled(channel, sent)
    judge.evaluate(1.0)
    assert (flow_of(channel), channel.findings) == (Flow.FLOWING, [])
    judge.evaluate(4.0)
    assert flow_of(channel) is Flow.FLOWING  # within the flowing window
    judge.evaluate(2.0)
    assert (flow_of(channel), channel.findings) == (Flow.STALLED, [])
    publisher.close()
    judge.evaluate(0.5)
    assert flow_of(channel) is Flow.WAITING_GAZEBO
    assert texts(channel)[0].startswith(f"no Gazebo publisher of {topic} in partition ")


def test_the_topic_alive_in_another_partition_names_it(rig: Rig) -> None:
    topic = unique("partition")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    rig.gazebo(native=Spelling.GZ, partition="elsewhere").advertise(topic, STRING)
    Judge(rig).evaluate()
    (text,) = texts(channel)
    assert text.startswith(
        f"the Gazebo topic {topic} is alive in another partition ('elsewhere': publisher "
        f"{STRING}), but the bridge uses partition '{rig.gz.partition}'; start the bridge with "
        "GZ_PARTITION=elsewhere (and IGN_PARTITION=elsewhere for Fortress)"
    )


def test_no_gazebo_at_all_is_said_once_for_the_bridge(rig: Rig) -> None:
    first = gz_to_ros(rig.add(string_spec(unique("alone_a"), Direction.GZ_TO_ROS)))
    second = gz_to_ros(rig.add(string_spec(unique("alone_b"), Direction.GZ_TO_ROS)))
    judge = Judge(rig)
    judge.until_confirmed()
    for channel in (first, second):
        assert flow_of(channel) is Flow.WAITING_GAZEBO
        assert [f.key for f in channel.findings] == ["no-peer"]
    (line,) = judge.logged
    assert line.startswith(
        "Nothing can flow: no Gazebo Transport process is heard at all; the bridge listens "
        f"with the in-memory network {rig.network.name}, partition '{rig.gz.partition}'."
    )
    # A process heard for a moment (a `gz topic -l` of another partition) is not a reason
    # to say it again: at most once a minute while it comes and goes.
    passing = rig.gazebo(partition="elsewhere")
    judge.evaluate(EXPLAIN_PERIOD)
    assert [f.key for f in first.findings] == ["gz-absent:publisher"]
    passing.close()
    judge.evaluate(EXPLAIN_PERIOD)
    judge.evaluate(EXPLAIN_PERIOD)
    assert judge.logged == [line]
    judge.evaluate(RELOG_AFTER)
    assert judge.logged == [line, line]


def test_an_absent_topic_suggests_similar_names_and_is_no_warning(rig: Rig) -> None:
    stem = f"odom_{uuid.uuid4().hex[:8]}"
    channel = gz_to_ros(rig.add(string_spec(f"/{stem}", Direction.GZ_TO_ROS)))
    rig.add(string_spec(f"/{stem}_cmd", Direction.ROS_TO_GZ))  # the bridge's own: not suggested
    rig.gazebo().advertise(f"/robot/{stem}", STRING)
    judge = Judge(rig)
    judge.until_confirmed()
    assert texts(channel) == [
        f"no Gazebo publisher of /{stem} in partition '{rig.gz.partition}' "
        f"(1 Gazebo process heard in any partition); similar topics: /robot/{stem}"
    ]
    # A side that is not there yet is explained, not warned about: an INFO line (a simulator
    # that starts after the bridge is the usual case) and an OK status.
    assert judge.logged == []
    assert f"{channel.describe()}: waiting for Gazebo: {texts(channel)[0]}" in judge.noted
    status = StatusTracker(rig.bridge).snapshot()[0]
    assert (status.level, status.message()) == (OK, f"waiting for Gazebo: {texts(channel)[0]}")


def test_the_waiting_half_of_a_bidirectional_entry_that_carries_is_no_warning(
    rig: Rig, world: RosWorld
) -> None:
    """An '@' entry's Gazebo topic often has no Gazebo subscriber at all: once the entry's
    Gazebo->ROS half carried, its ROS->Gazebo half waiting for one is shown, not logged."""
    topic = unique("both_ways")
    handle = rig.add(string_spec(topic, Direction.BIDIRECTIONAL))
    carrying, waiting = gz_to_ros(handle), ros_to_gz(handle)
    publisher = rig.gazebo().advertise(topic, STRING)
    inbox, _ = world.subscribe(String, topic)
    sent = publish_until(
        lambda i: publisher.publish(GzString(data=str(i))),
        lambda: bool(inbox.messages()),
        "a message in ROS",
    )
    settled(carrying, sent)
    judge = Judge(rig)
    judge.evaluate()
    # Messages passed before the first look: flowing at once, not "stalled" in a first status.
    assert flow_of(carrying) is Flow.FLOWING
    judge.evaluate(WARM_UP)
    judge.evaluate(CONFIRM_AFTER)
    assert flow_of(waiting) is Flow.WAITING_GAZEBO
    assert [f.key for f in waiting.findings] == ["gz-absent:subscriber"]
    assert judge.logged == judge.noted == []


def test_ros_to_gazebo_waits_for_gazebo_then_ros_then_flows(rig: Rig, world: RosWorld) -> None:
    topic = unique("r2g_flow")
    channel = ros_to_gz(rig.add(string_spec(topic, Direction.ROS_TO_GZ)))
    judge = Judge(rig)
    wrong = rig.gazebo(native=Spelling.GZ).subscribe(topic, Inbox(), "gz.msgs.Int32")
    judge.evaluate()
    assert flow_of(channel) is Flow.WAITING_GAZEBO
    (text,) = texts(channel)
    assert text.startswith(f"the Gazebo subscriber of {topic} (process ")
    assert text.endswith(
        "subscribes gz.msgs.Int32, but the bridge is configured with gz.msgs.StringMsg; "
        "gz.msgs.Int32 pairs with std_msgs/msg/Int32: set the Gazebo type to gz.msgs.Int32 "
        "and the ROS type to one of those"
    )
    wrong.close()

    inbox = Inbox()
    rig.gazebo(native=Spelling.GZ).subscribe_typed(topic, GzString, inbox)
    judge.evaluate(1.0)
    assert (flow_of(channel), channel.findings) == (Flow.WAITING_ROS, [])
    publisher = world.publisher(String, topic)
    wait_until(lambda: len(world.publishers(topic)) == 1, "the ROS publisher in the graph")
    judge.evaluate(1.0)
    assert (flow_of(channel), channel.findings) == (Flow.STALLED, [])
    sent = publish_until(
        lambda i: publisher.publish(String(data=str(i))),
        lambda: bool(inbox.messages()),
        "a message in Gazebo",
    )
    settled(channel, sent)
    judge.evaluate(1.0)
    assert (flow_of(channel), channel.findings) == (Flow.FLOWING, [])


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
