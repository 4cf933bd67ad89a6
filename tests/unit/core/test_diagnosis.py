"""The rules that explain a channel, on situations written by hand (no processes)."""

from __future__ import annotations

import dataclasses
import difflib

import pytest

from ros_gz_bridge_py.config import Direction
from ros_gz_bridge_py.converters.registry import default_registry
from ros_gz_bridge_py.core.diagnosis import Finding, Flow, RosEndpoint, Situation, findings, flow
from ros_gz_bridge_py.core.explain import type_hints
from ros_gz_bridge_py.transport.api import PUBLISHER, SUBSCRIBER, GraphEndpoint

HINTS = type_hints(default_registry())
PART = "sim"
PROCESS = "0123456789abcdef"


def situation(direction: Direction, **changes: object) -> Situation:
    base = Situation(
        direction=direction,
        ros_topic="/odom",
        ros_type="nav_msgs/msg/Odometry",
        gz_topic="/odom",
        gz_type="gz.msgs.Odometry",
        partition=PART,
        gz_endpoints=(),
        ros_endpoints=(),
        gz_peers=1,
        listening="ZeroMQ somewhere",
    )
    return dataclasses.replace(base, **changes)  # type: ignore[arg-type]


def endpoint(role: str, msg_type: str, partition: str = PART, **more: object) -> GraphEndpoint:
    return GraphEndpoint(role, partition, "/odom", msg_type, PROCESS, "tcp://10.0.0.5:4000", **more)  # type: ignore[arg-type]


def keys(found: list[Finding]) -> list[str]:
    return [f.key for f in found]


def test_a_publisher_of_either_spelling_is_the_gazebo_side() -> None:
    for seen in ("gz.msgs.Odometry", "ignition.msgs.Odometry"):
        ready = situation(Direction.GZ_TO_ROS, gz_endpoints=[endpoint(PUBLISHER, seen)])
        assert findings(ready, HINTS) == []
        assert flow(ready) is Flow.STALLED
        assert flow(dataclasses.replace(ready, since_message=1.0)) is Flow.FLOWING


def test_publisher_of_another_type_names_it_and_the_fix_in_the_configured_spelling() -> None:
    wrong = situation(Direction.GZ_TO_ROS, gz_endpoints=[endpoint(PUBLISHER, "ignition.msgs.Pose")])
    (finding,) = findings(wrong, HINTS)
    assert finding.key == "gz-type:publisher:ignition.msgs.Pose"
    assert "process 01234567 at tcp://10.0.0.5:4000" in finding.text
    assert "publishes ignition.msgs.Pose, but the bridge is configured with gz.msgs.Odometry" in (
        finding.text
    )
    assert "gz.msgs.Pose pairs with geometry_msgs/msg/Pose" in finding.text
    assert flow(wrong) is Flow.WAITING_GAZEBO


def test_a_pairing_type_is_proposed_alone() -> None:
    wrong = situation(
        Direction.GZ_TO_ROS,
        gz_type="ignition.msgs.OdometryWithCovariance",
        gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Odometry")],
    )
    (finding,) = findings(wrong, HINTS)
    assert "set the Gazebo type (gz_type_name) to ignition.msgs.Odometry" in finding.text


def test_image_bridge_sends_a_topic_of_other_types_to_parameter_bridge() -> None:
    """image_bridge takes no ROS or Gazebo type: its fix cannot be to set them."""
    hints = dataclasses.replace(HINTS, types_fixed_by="image_bridge")
    camera = situation(
        Direction.GZ_TO_ROS,
        ros_type="sensor_msgs/msg/Image",
        gz_type="gz.msgs.Image",
        gz_endpoints=[endpoint(PUBLISHER, "ignition.msgs.StringMsg")],
        ros_endpoints=[RosEndpoint("/viewer", "std_msgs/msg/String")],
    )
    gz_side, ros_side = findings(camera, hints)  # the Gazebo side first, as flow() waits
    assert gz_side.text.endswith(
        "; image_bridge cannot take other types: bridge the topic with parameter_bridge "
        "(set the Gazebo type to gz.msgs.StringMsg and the ROS type to std_msgs/msg/String)"
    )
    assert ros_side.text.endswith(
        "; image_bridge cannot take other types: bridge the topic with parameter_bridge "
        "(std_msgs/msg/String pairs with gz.msgs.StringMsg: set the ROS and Gazebo types to "
        "such a pair); or have /viewer subscribe to sensor_msgs/msg/Image"
    )
    (unpaired,) = findings(
        dataclasses.replace(
            camera, gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Nope")], ros_endpoints=()
        ),
        hints,
    )
    assert unpaired.text.endswith(
        "no converter takes gz.msgs.Nope (bridge_types --print-pairs lists the pairs)"
    )


def test_other_partition_no_peer_and_absent_are_told_apart() -> None:
    elsewhere = situation(
        Direction.GZ_TO_ROS, gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Odometry", "vm:root")]
    )
    (finding,) = findings(elsewhere, HINTS)
    assert finding.key == "partition:vm:root"
    assert "'vm:root': publisher gz.msgs.Odometry" in finding.text
    assert "GZ_PARTITION=vm:root" in finding.text
    assert "IGN_PARTITION=vm:root" in finding.text
    alone = situation(Direction.GZ_TO_ROS, gz_peers=0)
    assert keys(findings(alone, HINTS)) == ["no-peer"]
    assert "ZeroMQ somewhere" in findings(alone, HINTS)[0].text
    absent = situation(Direction.GZ_TO_ROS, gz_topics=["/model/robot/odom", "/clock", "/odometry"])
    (finding,) = findings(absent, HINTS)
    assert finding.key == "gz-absent:publisher"
    assert "similar topics: /model/robot/odom, /odometry" in finding.text
    # a namespace shared, the last names unlike (found by a new user: /robot1/clock was told
    # of /robot1/odom)
    namespaced = situation(
        Direction.GZ_TO_ROS, gz_topic="/robot1/clock", gz_topics=["/robot1/odom", "/robot1/clocks"]
    )
    (finding,) = findings(namespaced, HINTS)
    assert finding.text.endswith("similar topics: /robot1/clocks")


def test_the_partition_of_the_endpoints_a_channel_needs_is_proposed_first() -> None:
    """A Gazebo -> ROS channel needs a publisher: the partition of one is named (before, a
    subscriber's partition elsewhere was proposed as readily, another user's bridge there)."""
    both = situation(
        Direction.GZ_TO_ROS,
        gz_endpoints=[
            endpoint(SUBSCRIBER, "gz.msgs.Odometry", "another:bridge"),
            endpoint(PUBLISHER, "gz.msgs.Odometry", "vm:root"),
        ],
    )
    (finding,) = findings(both, HINTS)
    assert finding.key == "partition:vm:root"
    assert "; start the bridge with GZ_PARTITION=vm:root" in finding.text
    only_other_role = situation(
        Direction.ROS_TO_GZ, gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Odometry", "vm:root")]
    )
    (finding,) = findings(only_other_role, HINTS)
    assert "; if the simulator runs there, start the bridge with GZ_PARTITION=vm:root" in (
        finding.text
    )


def test_no_peer_over_zenoh_points_to_the_sessions_not_to_gz_ip() -> None:
    """GZ_IP and the partition cannot keep Zenoh sessions apart; the router and the
    endpoints can (the ZeroMQ advice was given for both)."""
    zeromq = findings(situation(Direction.GZ_TO_ROS, gz_peers=0), HINTS)[0].text
    assert "GZ_IP/IGN_IP on a network both reach" in zeromq
    listening = 'Zenoh client, connect ["tcp/10.0.0.5:7447"], listen [], multicast scouting off'
    (finding,) = findings(situation(Direction.GZ_TO_ROS, gz_peers=0, listening=listening), HINTS)
    assert finding.key == "no-peer"
    assert "GZ_IP" not in finding.text
    assert "GZ_PARTITION" not in finding.text
    assert finding.text.endswith(
        "Compare with the simulator's environment: the same GZ_TRANSPORT_IMPLEMENTATION "
        "(zenoh), and Zenoh sessions that reach each other: the router both connect to running "
        "and reached at its endpoint, or peers that connect or listen where the other does "
        "(ZENOH_CONFIG, GZ_TRANSPORT_ZENOH_CONFIG_OVERRIDE; docs/zenoh.md)"
    )


def test_no_peer_is_no_fault_before_discovery_listened_long_enough() -> None:
    early = situation(Direction.GZ_TO_ROS, gz_peers=0, peers_settled=False)
    (finding,) = findings(early, HINTS)
    assert finding.key == "gz-absent:publisher"
    assert not finding.fault
    assert "(0 Gazebo processes heard in any partition)" in finding.text
    assert flow(early) is Flow.WAITING_GAZEBO
    (settled,) = findings(dataclasses.replace(early, peers_settled=True), HINTS)
    assert (settled.key, settled.fault) == ("no-peer", False)  # a simulator not up yet
    (overdue,) = findings(dataclasses.replace(early, peers_settled=True, overdue=True), HINTS)
    assert (overdue.key, overdue.fault) == ("no-peer:overdue", True)
    assert overdue.text.startswith("still no Gazebo Transport process is heard at all; ")


def test_ros_to_gazebo_waits_for_a_registered_subscriber() -> None:
    typed_fortress = endpoint(SUBSCRIBER, "ignition.msgs.Twist")
    cmd = situation(
        Direction.ROS_TO_GZ,
        ros_type="geometry_msgs/msg/Twist",
        gz_type="gz.msgs.Twist",
        gz_endpoints=[endpoint(SUBSCRIBER, "")],
        since_message=0.1,
    )
    assert flow(cmd) is Flow.WAITING_GAZEBO  # messages go nowhere
    (declined,) = findings(cmd, HINTS)
    assert declined.key == f"gz-declined:{PROCESS}"
    assert "did not take gz.msgs.Twist under either spelling" in declined.text
    ok = dataclasses.replace(cmd, gz_endpoints=[typed_fortress], gz_subscriber_registered=True)
    assert findings(ok, HINTS) == []
    assert flow(ok) is Flow.FLOWING
    assert flow(dataclasses.replace(ok, since_message=None)) is Flow.WAITING_ROS
    other = dataclasses.replace(cmd, gz_endpoints=[endpoint(SUBSCRIBER, "gz.msgs.Vector3d")])
    assert keys(findings(other, HINTS)) == ["gz-type:subscriber:gz.msgs.Vector3d"]


def test_a_subscriber_registered_for_another_entry_of_the_topic_is_not_ours() -> None:
    """Two entries on one Gazebo topic (Twist and String on /cmd): a typed subscriber that
    registered for the Twist one does not take the String one's messages."""
    twist_taker = endpoint(SUBSCRIBER, "ignition.msgs.Twist", registered=True)
    text = situation(
        Direction.ROS_TO_GZ,
        ros_type="std_msgs/msg/String",
        gz_type="gz.msgs.StringMsg",
        gz_endpoints=[twist_taker],
    )
    assert keys(findings(text, HINTS)) == ["gz-type:subscriber:ignition.msgs.Twist"]
    assert flow(text) is Flow.WAITING_GAZEBO
    twist = dataclasses.replace(
        text, ros_type="geometry_msgs/msg/Twist", gz_type="gz.msgs.Twist",
        gz_subscriber_registered=True,
    )  # fmt: skip
    assert findings(twist, HINTS) == []


def test_ros_endpoints_of_another_type_or_qos_are_named_even_while_flowing() -> None:
    flowing = situation(
        Direction.GZ_TO_ROS,
        gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Odometry")],
        since_message=0.5,
        ros_endpoints=[
            RosEndpoint("/nav/amcl", "geometry_msgs/msg/PoseStamped"),
            RosEndpoint("/rviz", "nav_msgs/msg/Odometry", "ERROR: Best effort publisher"),
            RosEndpoint("/ok", "nav_msgs/msg/Odometry"),
        ],
    )
    found = findings(flowing, HINTS)
    assert keys(found) == [
        "ros-type:/nav/amcl:geometry_msgs/msg/PoseStamped",
        "ros-qos:/rviz",
    ]
    assert "uses geometry_msgs/msg/PoseStamped, but the bridge is configured with " in found[0].text
    assert "ERROR: Best effort publisher" in found[1].text
    assert "; set the entry's qos_profile (or qos_overrides./odom.*) to what" in found[1].text
    assert flow(flowing) is Flow.FLOWING
    # image_bridge has no entries: its qos parameter (before, the fix named entries)
    qos_setting = "image_bridge's qos parameter (default, sensor_data or system_default)"
    imaged = findings(flowing, dataclasses.replace(HINTS, qos_setting=qos_setting))
    assert "; set image_bridge's qos parameter (default, sensor_data or system_default) (or " in (
        imaged[1].text
    )


def test_a_discovered_bridge_names_the_rule_that_chose_its_types() -> None:
    discovered = situation(
        Direction.ROS_TO_GZ,
        ros_topic="/cmd_vel",
        ros_type="geometry_msgs/msg/Twist",
        gz_topic="/cmd_vel",
        gz_type="gz.msgs.Twist",
        gz_subscriber_registered=True,
        ros_endpoints=[
            RosEndpoint("/teleop", "std_msgs/msg/String"),
            RosEndpoint("/planner", "geometry_msgs/msg/TwistStamped"),
        ],
        discovered_by="typed Gazebo subscriber",
    )
    found = findings(discovered, HINTS)
    assert keys(found) == [
        "ros-type:/teleop:std_msgs/msg/String",
        "ros-type:/planner:geometry_msgs/msg/TwistStamped",
    ]
    assert (
        "uses std_msgs/msg/String, but the bridge took geometry_msgs/msg/Twist from discovery "
        "(typed Gazebo subscriber); std_msgs/msg/String does not pair with gz.msgs.Twist, "
        "which the Gazebo side takes: use geometry_msgs/msg/Twist in ROS"
    ) in found[0].text
    assert "TwistStamped also pairs with gz.msgs.Twist: write an entry with" in found[1].text


def test_similar_topics_are_found_once_while_the_list_stays_the_same(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The explainer asks first without the topic list, then with it, for every waiting channel
    every few seconds: the first look must not throw away what was found (201 waiting channels
    at rest cost 17% of a core when it did)."""
    compared: list[str] = []

    def close_matches(word: str, possibilities: list[str], n: int) -> list[str]:
        compared.append(word)
        return []

    monkeypatch.setattr(difflib, "get_close_matches", close_matches)
    absent = situation(Direction.GZ_TO_ROS, gz_topic="/odom_x")
    listed = dataclasses.replace(absent, gz_topics=["/model/robot/odom_x", "/clock"])
    for _ in range(3):
        findings(absent, HINTS)
        (finding,) = findings(listed, HINTS)
        assert "similar topics: /model/robot/odom_x" in finding.text
    assert compared == ["/odom_x"]


def test_a_lazy_channel_nobody_reads_waits_for_ros_whatever_it_passed_before() -> None:
    """The status table showed a lazy channel with its input closed as flowing for the few
    seconds after its last reader left."""
    idle = situation(
        Direction.GZ_TO_ROS,
        gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Odometry")],
        since_message=0.5,
        input_open=False,
    )
    assert flow(idle) is Flow.WAITING_ROS
    assert flow(dataclasses.replace(idle, input_open=True)) is Flow.FLOWING


def test_a_ros_publisher_of_another_type_is_also_told_to_publish_the_configured_one() -> None:
    """The fix only proposed retyping the entry, which breaks a Gazebo side that takes the
    configured type (found by a new user)."""
    teleop = situation(
        Direction.ROS_TO_GZ,
        ros_topic="/cmd",
        ros_type="geometry_msgs/msg/Twist",
        gz_type="gz.msgs.Twist",
        gz_endpoints=[endpoint(SUBSCRIBER, "ignition.msgs.Twist")],
        ros_endpoints=[RosEndpoint("/teleop", "std_msgs/msg/String")],
    )
    (finding,) = findings(teleop, HINTS)
    assert finding.text.endswith(
        "std_msgs/msg/String pairs with gz.msgs.StringMsg: set the ROS and Gazebo types to such "
        "a pair; or have /teleop publish geometry_msgs/msg/Twist"
    )


def test_a_one_way_channel_facing_the_other_role_is_told_to_turn() -> None:
    """'[' written for ']' said only 'no Gazebo publisher', while a Gazebo subscriber was
    there (found by a new user); half of a bidirectional entry is not told so."""
    wrong_way = situation(
        Direction.GZ_TO_ROS, gz_endpoints=[endpoint(SUBSCRIBER, "gz.msgs.Odometry")]
    )
    (finding,) = findings(wrong_way, HINTS)
    assert finding.key == "gz-absent:publisher"
    assert finding.text.endswith(
        "; a Gazebo subscriber of /odom is there: to carry messages the other way, bridge it "
        "ROS_TO_GZ (']' on the command line)"
    )
    half = dataclasses.replace(wrong_way, bidirectional=True)
    (finding,) = findings(half, HINTS)
    assert "the other way" not in finding.text
    backwards = situation(
        Direction.ROS_TO_GZ,
        gz_endpoints=[endpoint(PUBLISHER, "gz.msgs.Odometry")],
        ros_endpoints=[RosEndpoint("/nav", "nav_msgs/msg/Odometry")],
    )
    (finding,) = findings(backwards, HINTS)
    assert finding.text.endswith("bridge it GZ_TO_ROS ('[' on the command line)")


def test_a_name_outside_the_bridges_namespace_is_told_how_to_put_it_inside() -> None:
    """A robot's bridge under -r __ns:=/robot1 with 'odom': Gazebo names are not expanded
    by default, and the simulator has /robot1/odom."""
    waiting = situation(
        Direction.GZ_TO_ROS,
        gz_topics=["/robot1/odom", "/robot2/odom"],
        ros_namespace="/robot1",
    )
    (found,) = findings(waiting, HINTS)
    assert found.text.endswith(
        "similar topics: /robot1/odom, /robot2/odom; Gazebo names do not take the bridge's "
        "namespace /robot1 unless expand_gz_topic_names is true (-p "
        "expand_gz_topic_names:=true, with the entry's Gazebo name relative), or write "
        "/robot1/odom"
    )
    typed = dataclasses.replace(waiting, gz_typed=["/robot1/odom", "/robot2/odom"])
    assert "expand_gz_topic_names is true" in findings(typed, HINTS)[0].text  # shown for its type
    for elsewhere in ("/", "/robot3"):  # no such topic inside the namespace: no such hint
        other = dataclasses.replace(waiting, ros_namespace=elsewhere)
        assert "namespace" not in findings(other, HINTS)[0].text


def test_an_absent_topic_is_shown_the_topics_of_its_type_and_long_names_alike() -> None:
    """A simulator's own names (found by a new user: /model/turtlebot3_waffle/odometry for
    /odom, .../joint_state for /joint_states) were not proposed: compared whole, long names
    never looked close, and the type was not looked at."""
    odom = situation(
        Direction.GZ_TO_ROS,
        gz_topics=["/model/waffle/odometry", "/clock", "/world/default/model/waffle/joint_state"],
        gz_typed=["/model/waffle/odometry"],
    )
    (found,) = findings(odom, HINTS)
    assert found.text.endswith(
        "Gazebo publishers of gz.msgs.Odometry there: /model/waffle/odometry"
    )
    assert not found.fault
    joints = dataclasses.replace(odom, gz_topic="/joint_states", gz_typed=[])
    assert findings(joints, HINTS)[0].text.endswith(
        "similar topics: /world/default/model/waffle/joint_state"
    )
    fleet = [f"/robot{n}/odom" for n in range(1, 50)]
    many = dataclasses.replace(odom, gz_topic="/robot50/odom", gz_topics=fleet, gz_typed=fleet)
    assert "there: /robot1/odom, /robot2/odom, /robot3/odom and 46 more" in (
        findings(many, HINTS)[0].text
    )


def test_a_side_absent_while_the_partition_is_up_a_while_is_a_fault() -> None:
    absent = situation(Direction.GZ_TO_ROS, overdue=True)
    (found,) = findings(absent, HINTS)
    assert (found.key, found.fault) == ("gz-absent:publisher:overdue", True)
    assert found.text == (
        f"no Gazebo publisher of /odom in partition '{PART}' (1 Gazebo process heard in any "
        "partition), though the partition's other topics have been there a while: the "
        "simulator has none of this name"
    )
    gone = situation(Direction.GZ_TO_ROS, gz_peers=0, peers_lost=True)
    assert findings(gone, HINTS)[0].text.startswith(
        "the Gazebo Transport processes heard before are gone (a simulator that stopped, or a "
        "network that went away); the bridge listens with ZeroMQ somewhere."
    )
