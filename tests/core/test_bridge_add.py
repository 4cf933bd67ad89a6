"""What ``Bridge.add`` takes and refuses: specs made in Python checked as YAML entries are,
names ROS refuses, pairs without a converter, and what an earlier entry bridges already.

The bridge runs on a memory Gazebo node (``tests/core/harness.py``); its ROS side is an rclpy
node of this process.
"""

from __future__ import annotations

import dataclasses
import os
import threading
from typing import Any

import pytest
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from std_msgs.msg import String

from ros_gz_bridge_py.config import Direction, ServiceBridgeSpec, TopicBridgeSpec
from ros_gz_bridge_py.core.bridge import Bridge
from ros_gz_bridge_py.errors import BridgeError, ConfigError
from tests.core.harness import TEST_OPTIONS, Rig, RosWorld, gz_to_ros, unique

pytestmark = [pytest.mark.ros]  # rclpy participants, in this process

STRING, IGN_STRING = "gz.msgs.StringMsg", "ignition.msgs.StringMsg"


def string_spec(topic: str, direction: Direction) -> TopicBridgeSpec:
    return TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING, direction)


def test_a_direction_in_its_yaml_spelling_is_taken(rig: Rig) -> None:
    """An embedding user's ``TopicBridgeSpec(..., "GZ_TO_ROS")`` bridges, as the YAML does
    (it made a handle with no channel, silently)."""
    topic = unique("spelled")
    spec = string_spec(topic, Direction.GZ_TO_ROS)
    spelled = dataclasses.replace(spec, direction="GZ_TO_ROS")  # type: ignore[arg-type]
    handle = rig.add(spelled)
    assert [type(channel) for channel in handle.channels] == [type(gz_to_ros(handle))]
    assert isinstance(handle.spec, TopicBridgeSpec)
    assert handle.spec.direction is Direction.GZ_TO_ROS


def test_a_name_ros_refuses_is_said_without_rcl_source_locations(rig: Rig) -> None:
    """rclpy's error ended with ', at /project/src/rcl/expand_topic_name.c:73'."""
    topic = unique("refused") + "/0/cmd_pos"
    with pytest.raises(ConfigError) as raised:
        rig.add(string_spec(topic, Direction.ROS_TO_GZ))
    assert "topic name token must not start with a number" in str(raised.value)
    assert ", at " not in str(raised.value)
    assert str(raised.value).startswith(f"Failed to create a bridge for topic [{topic}]")


def test_an_entry_that_cannot_be_bridged_is_refused_whole(rig: Rig) -> None:
    topic = unique("refused")
    unpaired = TopicBridgeSpec(topic, topic, "std_msgs/msg/String", "gz.msgs.Twist")
    with pytest.raises(ConfigError, match=r"Failed to create a bridge for topic .*gz.msgs.Twist"):
        rig.add(unpaired)
    bad_profile = TopicBridgeSpec(topic, topic, "std_msgs/msg/String", STRING,
                                  qos_profile="NOT_A_PROFILE")  # fmt: skip
    with pytest.raises(ConfigError, match="unknown QoS profile"):
        rig.add(bad_profile)
    spec = string_spec(topic, Direction.GZ_TO_ROS)
    no_direction = dataclasses.replace(spec, direction="BOTH")  # type: ignore[arg-type]
    with pytest.raises(ConfigError, match="direction 'BOTH' is none of BIDIRECTIONAL, "):
        rig.add(no_direction)
    with pytest.raises(ConfigError, match="not str; parse_cli_args and parse_yaml"):
        rig.add(f"{topic}@std_msgs/msg/String@{STRING}")  # type: ignore[arg-type]
    assert rig.bridge.handles == []
    assert rig.gazebo().topic_info(topic) == []
    rig.world.run(rig.bridge.close)
    with pytest.raises(BridgeError, match=rf"closed; TopicBridgeSpec\(ros_topic='{topic}'"):
        rig.add(string_spec(topic, Direction.GZ_TO_ROS))


@pytest.mark.parametrize(
    ("change", "refusal"),
    [
        ({"ros_type": String}, "ros_type must be a non-empty string such as 'std_msgs/msg/"
         "String', not the class std_msgs.msg._string.String"),
        ({"gz_topic": ""}, "gz_topic must be a non-empty string"),
        ({"max_rate": -5}, "max_rate must be a number of messages per second >= 0"),
        ({"publisher_queue": -1}, "publisher_queue must be a non-negative integer, got -1"),
        ({"subscriber_queue": 1 << 30}, "subscriber_queue must be at most 16777216"),
        ({"lazy": "maybe"}, "lazy must be true or false, got 'maybe'"),
    ],
)  # fmt: skip
def test_a_spec_made_in_python_is_checked_as_a_yaml_entry_is(
    rig: Rig, change: dict[str, Any], refusal: str
) -> None:
    """Before: a message class failed deep in the registry (AttributeError), max_rate -5 was
    taken, publisher_queue -1 reached rcl (its error, then rcutils' 'overwriting' block)."""
    topic = unique("unchecked")
    spec = dataclasses.replace(string_spec(topic, Direction.GZ_TO_ROS), **change)
    with pytest.raises(ConfigError) as raised:
        rig.add(spec)
    assert str(raised.value) == f"topic bridge '{topic}': {refusal}" or refusal in str(raised.value)
    assert str(raised.value).startswith(f"topic bridge '{topic}': ")
    assert rig.bridge.handles == []


def test_a_spec_made_in_python_takes_what_the_yaml_takes(rig: Rig) -> None:
    """The deprecated ``IGN_TO_ROS`` (refused before) and numbers written as text."""
    topic = unique("spelled")
    spec = dataclasses.replace(
        string_spec(topic, Direction.GZ_TO_ROS),
        direction="IGN_TO_ROS",  # type: ignore[arg-type]
        publisher_queue="5",  # type: ignore[arg-type]
        max_rate="20",  # type: ignore[arg-type]
    )
    handle = rig.add(spec)
    assert isinstance(handle.spec, TopicBridgeSpec)
    assert (handle.spec.direction, handle.spec.publisher_queue, handle.spec.max_rate) == (
        Direction.GZ_TO_ROS, 5, 20.0
    )  # fmt: skip
    assert gz_to_ros(handle).qos.depth == 5


def test_what_a_bridge_carries_already_is_refused_a_second_time(rig: Rig) -> None:
    """The C++ bridge builds both, and every message arrives twice."""
    topic = unique("twice")
    first = rig.add(
        dataclasses.replace(
            string_spec(topic, Direction.GZ_TO_ROS), source="a.yaml entry 1 (line 1)"
        )
    )
    # the same channel spelled otherwise: a relative name, the Fortress type name
    again = TopicBridgeSpec(topic.lstrip("/"), topic, "std_msgs/msg/String", IGN_STRING,
                            Direction.GZ_TO_ROS, source="a.yaml entry 2 (line 5)")  # fmt: skip
    with pytest.raises(ConfigError) as raised:
        rig.add(again)
    assert str(raised.value) == (
        f"a.yaml entry 2 (line 5): ROS {topic} (std_msgs/msg/String) and Gazebo {topic} "
        f"({IGN_STRING}) GZ_TO_ROS is bridged already "
        "by a.yaml entry 1 (line 1); a second bridge would pass every message twice. Remove "
        "one of the two entries (Bridge.remove the earlier handle first to replace it)"
    )
    assert rig.bridge.handles == [first]
    other_way = rig.add(string_spec(topic, Direction.ROS_TO_GZ))  # another direction: taken
    elsewhere = rig.add(TopicBridgeSpec(topic + "_b", topic, "std_msgs/msg/String", STRING,
                                        Direction.GZ_TO_ROS))  # fmt: skip
    rig.remove(first)
    replaced = rig.add(again)
    assert rig.bridge.handles == [other_way, elsewhere, replaced]


def test_a_service_bridged_already_is_refused_a_second_time(rig: Rig) -> None:
    """A second ROS server of the name would answer every call again, whatever its types."""
    name = unique("control")
    first = rig.add(ServiceBridgeSpec(name, "ros_gz_interfaces/srv/ControlWorld"))
    again = ServiceBridgeSpec(name.lstrip("/"), "ros_gz_interfaces/srv/ControlWorld",
                              "gz.msgs.WorldControl", "gz.msgs.Boolean", "argument 2")  # fmt: skip
    with pytest.raises(ConfigError) as raised:
        rig.add(again)
    assert str(raised.value).startswith(
        f"argument 2: the ROS service {name} is bridged already by an earlier Bridge.add; "
        "a second bridge would pass every call twice."
    )
    assert rig.bridge.handles == [first]


@pytest.mark.parametrize(
    ("ros_topic", "gz_topic", "fix"),
    [
        (
            "/robot-1/odom", "/robot-1/odom",
            "; [/robot-1/odom] is no valid ROS name: a ROS name is letters, digits and "
            "underscores between its '/' (no '-', '.' or spaces), though Gazebo takes it: set "
            "ros_topic_name to a ROS name and gz_topic_name to this one",
        ),
        (
            "bad name", "/fine",
            "; [bad name] is no valid ROS name: a ROS name is letters, digits and underscores "
            "between its '/' (no '-', '.' or spaces)",
        ),
        (
            "/fine", "~/private",
            "; -p expand_gz_topic_names:=true expands '~' in YAML entries as in ROS names",
        ),
    ],
)  # fmt: skip
def test_a_name_one_side_refuses_is_told_what_to_write(
    rig: Rig, ros_topic: str, gz_topic: str, fix: str
) -> None:
    """Found by a new user: rcl's 'failed to resolve name' did not say that the ROS name was
    the one refused (Gazebo takes '-'), nor '~' in a Gazebo name how to get the namespace."""
    spec = TopicBridgeSpec(ros_topic, gz_topic, "std_msgs/msg/String", "gz.msgs.StringMsg")
    with pytest.raises(ConfigError) as raised:
        rig.add(spec)
    assert str(raised.value).endswith(fix)
    assert rig.bridge.handles == []


def test_two_bridges_on_one_node_bridge_a_topic_once_and_name_their_helpers_apart(
    rig: Rig,
) -> None:
    """Two Bridge objects on one node bridged one topic twice (every message arrived twice)
    and made two helper nodes of one name."""
    topic, other = unique("twice"), unique("once")
    rig.add(string_spec(topic, Direction.BIDIRECTIONAL))  # its loop guard needs the side node
    second = rig.world.run(lambda: Bridge(rig.node, gz_node=rig.gz, options=TEST_OPTIONS))
    try:
        with pytest.raises(ConfigError, match=r"bridged already by an earlier Bridge\.add"):
            rig.world.run(lambda: second.add(string_spec(topic, Direction.GZ_TO_ROS)))
        rig.world.run(lambda: second.add(string_spec(other, Direction.BIDIRECTIONAL)))
        name = rig.node.get_name()
        helpers = {n for n in rig.node.get_node_names() if n.startswith(f"_{name}_side")}
        assert helpers == {f"_{name}_side", f"_{name}_side_2"}
    finally:
        rig.world.run(second.close)
    # Closed, it holds nothing: the topic it took may be bridged again.
    rig.add(string_spec(other, Direction.GZ_TO_ROS))


def test_options_are_given_by_keyword() -> None:
    """``Bridge(node, BridgeOptions(...))`` took the options as the Gazebo node and failed
    at the first add with "'BridgeOptions' object has no attribute ..."."""
    untyped: Any = Bridge  # as an untyped program calls it
    with pytest.raises(TypeError, match="positional argument"):
        untyped(object(), TEST_OPTIONS)


def test_a_bridge_that_cannot_start_leaves_nothing_open(world: RosWorld) -> None:
    """Each failed construction left its own Gazebo node running (a thread and 19 fds)."""
    node = world.create_node(unique("destroyed").strip("/"))
    node.destroy_node()
    before = threading.active_count(), len(os.listdir("/proc/self/fd"))
    for _ in range(3):
        with pytest.raises(_rclpy.InvalidHandle):  # the node is destroyed
            Bridge(node, options=TEST_OPTIONS)
    assert (threading.active_count(), len(os.listdir("/proc/self/fd"))) == before
