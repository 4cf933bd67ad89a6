"""Flow states and explanations in one process: ``Explainer.evaluate`` on real channels.

The bridge's own explain timer is off (the test options); each test makes an
:class:`~ros_gz_bridge_py.core.explain.Explainer` with a clock it moves, so warm-up,
confirmation and "logged once" are checked at exact moments instead of waited for. The
Gazebo side is memory nodes (``observe`` shows their endpoints, every partition); the ROS
side is the graph of this process's contexts.
"""

from __future__ import annotations

import uuid

import pytest
from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction
from ros_gz_bridge_py.core.diagnosis import Flow
from ros_gz_bridge_py.core.explain import (
    CONFIRM_AFTER,
    EXPLAIN_PERIOD,
    PATIENCE,
    SIMULATOR_AFTER,
    WARM_UP,
)
from ros_gz_bridge_py.core.status import OK, WARN, StatusTracker
from ros_gz_bridge_py.msgs.names import Spelling
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
from tests.core.judge import STRING, GzString, Judge, carry, flow_of, spec, string_spec, texts

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process


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
    carry(channel, publisher, inbox)
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


def test_a_channel_whose_every_message_fails_is_not_flowing(rig: Rig) -> None:
    """Counted by what it received, a channel that published nothing (every image shorter
    than its size) showed "flowing" (found by a new user)."""
    topic = unique("failing")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    publisher = rig.gazebo().advertise(topic, STRING)
    judge = Judge(rig)
    judge.evaluate()
    for _ in range(3):
        publisher.publish_raw(b"\xff\xff\xff")  # not a protobuf message
    wait_until(lambda: channel.stats.conversion_errors == 3, "three errors")
    judge.evaluate(1.0)
    assert flow_of(channel) is Flow.STALLED
    assert channel.stats.published == 0


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
    # A simulator that starts after the bridge is the usual case: an INFO line, an OK status.
    assert judge.logged == []
    (line,) = judge.noted
    listens = f"the bridge listens with the in-memory network {rig.network.name}, partition"
    assert line.startswith(
        f"Nothing can flow: no Gazebo Transport process is heard at all; {listens}"
    )
    assert StatusTracker(rig.bridge).snapshot()[0].level == OK
    # A process heard for a moment (a `gz topic -l` of another partition) is not a reason
    # to say it again: at most once a minute while it comes and goes.
    passing = rig.gazebo(partition="elsewhere")
    judge.evaluate(EXPLAIN_PERIOD)
    assert [f.key for f in first.findings] == ["gz-absent:publisher"]
    passing.close()
    judge.evaluate(EXPLAIN_PERIOD)
    judge.evaluate(EXPLAIN_PERIOD)
    assert judge.noted == [line]
    # Nobody after PATIENCE: a fault now, said once as a warning.
    judge.evaluate(PATIENCE)
    judge.evaluate(CONFIRM_AFTER)
    (warning,) = judge.logged
    assert warning.startswith(
        f"Nothing can flow: still no Gazebo Transport process is heard at all; {listens}"
    )
    assert StatusTracker(rig.bridge).snapshot()[0].level == WARN
    # A simulator that comes is said once it stayed; its leaving is said at once, as such,
    # and is a fault only PATIENCE after it (a simulator restarting is the usual case).
    simulator = rig.gazebo()
    simulator.advertise(unique("clock"), STRING)  # in the bridge's partition
    judge.evaluate(EXPLAIN_PERIOD)
    judge.evaluate(EXPLAIN_PERIOD)
    heard = "Gazebo Transport heard now (1 process in any partition)"
    assert bridge_wide(judge.noted) == [line, heard]
    judge.evaluate(SIMULATOR_AFTER)
    simulator.close()
    judge.evaluate(EXPLAIN_PERIOD)
    judge.evaluate(CONFIRM_AFTER)
    gone = (
        "Nothing can flow: the Gazebo Transport processes heard before are gone (a simulator "
        f"that stopped, or a network that went away); {listens}"
    )
    assert bridge_wide(judge.noted)[2].startswith(gone)
    assert len(bridge_wide(judge.logged)) == 1
    judge.evaluate(PATIENCE)
    judge.evaluate(CONFIRM_AFTER)
    assert bridge_wide(judge.logged)[1].startswith(gone)
    # A tool that comes and goes within seconds (`gz topic -e`) is no simulator: its leaving
    # is not said again within the minute.
    tool = rig.gazebo()
    tool.advertise(unique("echo"), STRING)
    judge.evaluate(EXPLAIN_PERIOD)
    judge.evaluate(EXPLAIN_PERIOD)
    tool.close()
    judge.evaluate(EXPLAIN_PERIOD)
    judge.evaluate(EXPLAIN_PERIOD)
    assert bridge_wide(judge.noted)[3:] == [heard]
    assert len(bridge_wide(judge.logged)) == 2


def bridge_wide(lines: list[str]) -> list[str]:
    """The lines said of the whole bridge, not of one channel."""
    return [line for line in lines if not line.startswith(("GZ->ROS", "ROS->GZ"))]


def test_an_absent_topic_suggests_similar_names_and_is_no_warning(rig: Rig) -> None:
    stem = f"odom_{uuid.uuid4().hex[:8]}"
    channel = gz_to_ros(rig.add(string_spec(f"/{stem}", Direction.GZ_TO_ROS)))
    rig.add(string_spec(f"/{stem}_cmd", Direction.ROS_TO_GZ))  # the bridge's own: not suggested
    rig.gazebo().advertise(f"/robot/{stem}", STRING)
    judge = Judge(rig)
    judge.until_confirmed()
    assert texts(channel) == [
        f"no Gazebo publisher of /{stem} in partition '{rig.gz.partition}' "
        f"(1 Gazebo process heard in any partition); Gazebo publishers of {STRING} there: "
        f"/robot/{stem}"
    ]
    # A side that is not there yet is explained, not warned about: an INFO line (a simulator
    # that starts after the bridge is the usual case) and an OK status.
    assert judge.logged == []
    assert f"{channel.describe()}: waiting for Gazebo: {texts(channel)[0]}" in judge.noted
    status = StatusTracker(rig.bridge).snapshot()[0]
    assert (status.level, status.message()) == (OK, f"waiting for Gazebo: {texts(channel)[0]}")


def test_a_topic_still_absent_while_the_simulator_is_up_is_a_warning_until_it_flows(
    rig: Rig, world: RosWorld
) -> None:
    """Absent at first is a simulator starting (INFO, OK); absent while the partition's other
    topics have been there for PATIENCE is a name that differs (WARN); flowing after a
    cause was said is said too (the last word on a channel was "waiting" for good)."""
    topic = unique("late")
    channel = gz_to_ros(rig.add(string_spec(topic, Direction.GZ_TO_ROS)))
    simulator = rig.gazebo()
    simulator.advertise(unique("clock"), STRING)  # the simulator is up, without the topic
    inbox, _ = world.subscribe(String, topic)
    judge = Judge(rig)
    judge.until_confirmed()
    assert judge.logged == []
    assert [f.key for f in channel.findings] == ["gz-absent:publisher"]
    judge.evaluate(PATIENCE)
    judge.evaluate(CONFIRM_AFTER)
    (warning,) = judge.logged
    assert warning.startswith(f"{channel.describe()}: waiting for Gazebo: no Gazebo publisher")
    assert "though the partition's other topics have been there a while" in warning
    assert StatusTracker(rig.bridge).snapshot()[0].level == WARN

    publisher = simulator.advertise(topic, STRING)
    carry(channel, publisher, inbox)
    judge.evaluate(1.0)
    assert judge.noted[-1] == f"{channel.describe()}: flowing"
    judge.evaluate(1.0)
    assert judge.noted[-1] == f"{channel.describe()}: flowing"  # said once
    assert judge.noted.count(judge.noted[-1]) == 1


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
    carry(carrying, publisher, inbox)
    judge = Judge(rig)
    judge.evaluate()
    # Messages passed before the first look: flowing at once, not "stalled" in a first status.
    assert flow_of(carrying) is Flow.FLOWING
    judge.evaluate(WARM_UP)
    judge.evaluate(CONFIRM_AFTER)
    assert flow_of(waiting) is Flow.WAITING_GAZEBO
    assert [f.key for f in waiting.findings] == ["gz-absent:subscriber"]
    assert judge.logged == judge.noted == []
    judge.evaluate(PATIENCE)  # nor is it ever a fault: the Gazebo topic has no subscriber
    assert [f.key for f in waiting.findings] == ["gz-absent:subscriber"]
    assert judge.logged == []


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
        "set the Gazebo type to gz.msgs.Int32 and the ROS type to std_msgs/msg/Int32"
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
