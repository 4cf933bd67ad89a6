"""What discovered bridging makes of a graph and the ROS publishers (``core/discovery_plan.py``),
and the rate limiter."""

from __future__ import annotations

import pytest

from ros_gz_bridge_py.config import Direction, TopicBridgeSpec, parse_yaml
from ros_gz_bridge_py.config.discovered import AutoBridgeRules, auto_bridge_rules
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.core.discovery_plan import (
    AUTO_SOURCE,
    BY_ENTRY,
    BY_GZ_PUBLISHER,
    BY_GZ_SUBSCRIBER,
    BY_ROS_PUBLISHER,
    Plan,
    RosPublishers,
    plan,
    ros_names_to_read,
    same_bridge,
    sightings,
)
from ros_gz_bridge_py.core.rate_limit import RateLimiter, rate_limiter
from ros_gz_bridge_py.msgs.names import Spelling
from ros_gz_bridge_py.transport.api import PUBLISHER, SUBSCRIBER, GraphEndpoint

PARTITION = "sim"
ALL = auto_bridge_rules(True, [], [])


def pub(topic: str, msg_type: str, partition: str = PARTITION) -> GraphEndpoint:
    return GraphEndpoint(PUBLISHER, partition, topic, msg_type, "p1", "tcp://x")


def sub(topic: str, msg_type: str = "", process: str = "p2") -> GraphEndpoint:
    return GraphEndpoint(SUBSCRIBER, PARTITION, topic, msg_type, process, "")


def planned(
    endpoints: list[GraphEndpoint],
    rules: AutoBridgeRules = ALL,
    yaml_text: str = "",
    explicit: frozenset[str] = frozenset(),
    *,
    ros: RosPublishers | None = None,
    spellings: dict[str, Spelling] | None = None,
) -> Plan:
    patterns = parse_yaml(yaml_text, "p.yaml").patterns if yaml_text else ()
    found = sightings(endpoints, PARTITION, (spellings or {}).get)
    return plan(
        found, patterns=patterns, rules=rules, registry=default_registry(), explicit=explicit,
        ros_publishers=ros,
    )  # fmt: skip


def test_publishers_go_to_ros_and_typed_subscribers_come_from_ros() -> None:
    result = planned([
        pub("/model/box::link/odometry", "ignition.msgs.Odometry"),
        sub("/model/box/cmd_vel", "gz.msgs.Twist"),
        pub("/clock", "gz.msgs.Clock", partition="elsewhere"),
    ])  # fmt: skip
    assert result.specs == {
        "/model/box::link/odometry": TopicBridgeSpec(
            "model/box/link/odometry", "/model/box::link/odometry", "nav_msgs/msg/Odometry",
            "ignition.msgs.Odometry", Direction.GZ_TO_ROS, lazy=True, source=AUTO_SOURCE,
            discovered_by=BY_GZ_PUBLISHER,
        ),
        "/model/box/cmd_vel": TopicBridgeSpec(
            "model/box/cmd_vel", "/model/box/cmd_vel", "geometry_msgs/msg/Twist",
            "gz.msgs.Twist", Direction.ROS_TO_GZ, lazy=True, source=AUTO_SOURCE,
            discovered_by=BY_GZ_SUBSCRIBER,
        ),
    }  # fmt: skip


def test_what_is_not_bridged_says_why() -> None:
    result = planned([
        sub("/fortress/cmd_vel"),
        pub("/mixed", "gz.msgs.Twist"),
        GraphEndpoint(PUBLISHER, PARTITION, "/mixed", "gz.msgs.Pose", "p3", ""),
        pub("/unpaired", "gz.msgs.SdfGeneratorConfig"),
        pub("/a::b", "gz.msgs.Twist"),
        pub("/a/b", "gz.msgs.Twist"),
    ])  # fmt: skip
    assert set(result.specs) == {"/a/b"}
    assert "subscribers announce no type (gz-transport 11/12" in result.skipped["/fortress/cmd_vel"]
    assert "disagree on the type" in result.skipped["/mixed"]
    assert "pairs with no ROS type" in result.skipped["/unpaired"]
    assert result.skipped["/a::b"] == "its ROS name a/b is taken by /a/b"


def test_a_topic_with_a_publisher_takes_its_type_even_with_untyped_subscribers() -> None:
    result = planned([pub("/scan", "ignition.msgs.LaserScan"), sub("/scan")])
    assert result.specs["/scan"].direction is Direction.GZ_TO_ROS
    assert result.specs["/scan"].ros_type == "sensor_msgs/msg/LaserScan"


def test_allow_and_deny_hold_and_explicit_entries_keep_their_settings() -> None:
    endpoints = [
        pub("/model/r1/odometry", "gz.msgs.Odometry"),
        pub("/model/r1/camera", "gz.msgs.Image"),
        pub("/clock", "gz.msgs.Clock"),
    ]
    rules = auto_bridge_rules(True, ["^/model/"], ["camera"])
    assert set(planned(endpoints, rules).specs) == {"/model/r1/odometry"}
    explicit = frozenset({"/model/r1/odometry"})
    assert set(planned(endpoints, explicit=explicit).specs) == {"/model/r1/camera", "/clock"}
    assert planned(endpoints, AutoBridgeRules()).specs == {}


def test_yaml_patterns_come_first_and_work_without_auto_bridge() -> None:
    yaml_text = (
        "- gz_topic_name: /model/*/odometry\n  ros_topic_name: /*/odom\n  max_rate: 10\n"
        "- gz_topic_name: /model/*/cmd_vel\n  gz_type_name: gz.msgs.Twist\n"
        "- topic_name: /imu\n  ros_type_name: sensor_msgs/msg/Imu\n"
    )
    result = planned(
        [
            pub("/model/r1/odometry", "ignition.msgs.Odometry"),
            sub("/model/r2/cmd_vel"),  # Fortress: no type, the entry gives it
            pub("/model/r1/pose", "gz.msgs.Pose"),
        ],
        AutoBridgeRules(),
        yaml_text,
    )
    odom = result.specs["/model/r1/odometry"]
    assert (odom.ros_topic, odom.ros_type, odom.direction, odom.max_rate) == (
        "/r1/odom", "nav_msgs/msg/Odometry", Direction.GZ_TO_ROS, 10.0
    )  # fmt: skip
    assert odom.source == "p.yaml entry 1 (line 1)"
    cmd = result.specs["/model/r2/cmd_vel"]
    assert (cmd.ros_topic, cmd.ros_type, cmd.gz_type, cmd.direction) == (
        "/model/r2/cmd_vel", "geometry_msgs/msg/Twist", "gz.msgs.Twist", Direction.ROS_TO_GZ
    )  # fmt: skip
    assert "/model/r1/pose" not in result.specs
    assert (odom.discovered_by, cmd.discovered_by) == (BY_GZ_PUBLISHER, BY_ENTRY)


def test_a_left_out_type_needs_discovery_unless_the_other_type_decides() -> None:
    yaml_text = "- topic_name: /imu\n  ros_type_name: sensor_msgs/msg/Imu\n  direction: ROS_TO_GZ\n"
    result = planned([sub("/imu")], AutoBridgeRules(), yaml_text)
    assert result.specs["/imu"].gz_type == "gz.msgs.IMU"
    mismatch = "- topic_name: /x\n  gz_type_name: gz.msgs.Twist\n"
    result = planned([pub("/x", "gz.msgs.Pose")], AutoBridgeRules(), mismatch)
    assert "says gz.msgs.Twist, but Gazebo shows gz.msgs.Pose" in result.skipped["/x"]


CMD_VEL = "/model/robot1/cmd_vel"


def test_an_untyped_subscriber_takes_the_type_of_the_ros_publisher() -> None:
    ros = {"model/robot1/cmd_vel": ("geometry_msgs/msg/Twist",)}
    assert ros_names_to_read(
        sightings([sub(CMD_VEL), pub("/odom", "gz.msgs.Odometry")], "sim")
    ) == ["model/robot1/cmd_vel"]
    result = planned([sub(CMD_VEL)], ros=ros)
    assert result.specs[CMD_VEL] == TopicBridgeSpec(
        "model/robot1/cmd_vel", CMD_VEL, "geometry_msgs/msg/Twist", "gz.msgs.Twist",
        Direction.ROS_TO_GZ, lazy=True, source=AUTO_SOURCE, discovered_by=BY_ROS_PUBLISHER,
    )  # fmt: skip
    # the subscriber's process is known to be Fortress: its spelling
    fortress = planned([sub(CMD_VEL)], ros=ros, spellings={"p2": Spelling.IGNITION})
    assert fortress.specs[CMD_VEL].gz_type == "ignition.msgs.Twist"
    # two processes of two lines: both spellings (the canonical one; both are announced)
    mixed = planned(
        [sub(CMD_VEL), sub(CMD_VEL, process="p3")], ros=ros,
        spellings={"p2": Spelling.IGNITION, "p3": Spelling.GZ},
    )  # fmt: skip
    assert mixed.specs[CMD_VEL].gz_type == "gz.msgs.Twist"
    # a ROS type that pairs with several Gazebo types: its default (bridge_types --get-ros-to-gz)
    odometry = planned([sub("/odom_in")], ros={"odom_in": ("nav_msgs/msg/Odometry",)})
    assert odometry.specs["/odom_in"].gz_type == "gz.msgs.Odometry"


def test_an_untyped_subscriber_without_a_usable_ros_publisher_is_skipped_with_why() -> None:
    result = planned(
        [sub("/a"), sub("/b"), sub("/c"), pub("/d", "gz.msgs.Pose"), sub("/d")],
        ros={
            "b": ("geometry_msgs/msg/Twist", "std_msgs/msg/String"),
            "c": ("rcl_interfaces/msg/ParameterEvent",),
            "d": ("std_msgs/msg/String",),  # Gazebo publishes: Gazebo -> ROS, ROS aside
        },
    )
    assert "no ROS node publishes on a to tell it" in result.skipped["/a"]
    assert "ROS publishers disagree on the type" in result.skipped["/b"]
    assert "rcl_interfaces/msg/ParameterEvent pairs with no Gazebo type" in result.skipped["/c"]
    assert (result.specs["/d"].ros_type, result.specs["/d"].discovered_by) == (
        "geometry_msgs/msg/Pose", BY_GZ_PUBLISHER
    )  # fmt: skip
    # without auto_bridge, the ROS graph decides nothing
    assert planned([sub("/a")], AutoBridgeRules(), ros={"a": ("std_msgs/msg/String",)}) == Plan()


def test_a_typed_subscriber_wins_over_the_ros_publisher_and_says_so() -> None:
    endpoints = [sub(CMD_VEL, "gz.msgs.Twist")]
    result = planned(endpoints, ros={"model/robot1/cmd_vel": ("std_msgs/msg/String",)})
    spec = result.specs[CMD_VEL]
    assert (spec.ros_type, spec.gz_type, spec.discovered_by) == (
        "geometry_msgs/msg/Twist", "gz.msgs.Twist", BY_GZ_SUBSCRIBER
    )  # fmt: skip
    assert (
        "use std_msgs/msg/String, which does not pair with gz.msgs.Twist" in (result.notes[CMD_VEL])
    )
    # a ROS type that pairs with the Gazebo type is taken over the default
    stamped = planned(
        [sub("/pose", "gz.msgs.Pose")], ros={"pose": ("geometry_msgs/msg/PoseStamped",)}
    )
    assert stamped.specs["/pose"].ros_type == "geometry_msgs/msg/PoseStamped"
    assert stamped.notes == {}


def test_a_bridge_is_the_same_whichever_rule_and_spelling_chose_its_types() -> None:
    ros = {"model/robot1/cmd_vel": ("geometry_msgs/msg/Twist",)}
    inferred = planned([sub(CMD_VEL)], ros=ros).specs[CMD_VEL]
    # once the Fortress subscriber took our publisher, discovery shows its type
    typed = planned([sub(CMD_VEL, "ignition.msgs.Twist")], ros=ros).specs[CMD_VEL]
    assert inferred != typed
    assert same_bridge(inferred, typed)
    other = planned([sub(CMD_VEL)], ros={"model/robot1/cmd_vel": ("std_msgs/msg/String",)})
    assert not same_bridge(inferred, other.specs[CMD_VEL])


def test_rate_limiter_passes_one_message_per_period_on_average() -> None:
    clock = [0.0]
    limiter = RateLimiter(10.0, now=lambda: clock[0])
    passed = 0
    for step in range(1000):  # 10 s at 100 Hz with jitter
        clock[0] = step * 0.01 + (0.003 if step % 3 else 0.0)
        passed += limiter.admit()
    assert 99 <= passed <= 101
    clock[0] = 100.0  # after a pause: one message, no burst
    assert [limiter.admit() for _ in range(5)] == [True, False, False, False, False]


@pytest.mark.parametrize(
    ("entry", "node", "limited"), [(None, 0.0, False), (None, 5.0, True), (0.0, 5.0, False)]
)
def test_entry_rate_wins_over_the_node_rate(
    entry: float | None, node: float, limited: bool
) -> None:
    assert (rate_limiter(entry, node) is not None) is limited
