"""Discovered bridging end to end (issue 16, points 1 and 2), with real peers and no YAML.

ZeroMQ: real Fortress processes (the C++ ``ign_peer`` on ign-transport 11) publish
``ignition.msgs.*`` types, one under a ``::`` name with a token starting with a digit; they
appear in ROS under valid names, carry their values, and go when their process exits; a denied
topic never appears; a Fortress subscriber, whose type the protocol does not tell, is skipped
and said once. Zenoh: our ``ZenohGzNode`` process publishes and has a typed subscriber, so
values go both ways. ``--discover`` prints a YAML that, fed back, bridges the same topics.

Issue 23 item 5: a Fortress ``cmd_vel`` subscriber (no type on the wire) beside a ROS publisher
gets the ROS publisher's values, under ``auto_bridge`` and through a ``--discover`` file; a
typed subscriber (a Zenoh peer: its tokens carry the type) beside a ROS publisher of another
type is bridged with the Gazebo type and the mismatch is explained; ``--check`` with
``auto_bridge`` checks the inferred entry and names its rule; a
Fortress subscriber that subscribed before the bridge is invisible until a publisher of its
type is announced on its topic.
"""

from __future__ import annotations

import json
import re
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest
from geometry_msgs.msg import Pose, Twist
from nav_msgs.msg import Odometry
from std_msgs.msg import String

from ros_gz_bridge_py.transport import create_gz_node
from ros_gz_bridge_py.transport.api import SUBSCRIBER
from testing.behaviour_harness import (
    WAIT,
    RosSide,
    bridge_command,
    probe,
    publish_until,
    started,
)
from testing.e2e_harness import PARAMETER_BRIDGE
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)
from testing.loopback import free_port, zenoh_env

__all__ = ["probe", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]

#: The check's window in this test: its half, when the discovered entries are asked for, holds
#: the C++ peer's start on a busy machine.
CHECK_WINDOW = 12
GAZEBO_SIDE = Path(__file__).resolve().parent / "e2e_zenoh_gazebo.py"


def ros_topics(ros: RosSide) -> dict[str, list[str]]:
    return dict(ros.run(ros.node.get_topic_names_and_types))


def odometry_peer(topic: str) -> PeerProcess:
    return start_peer(
        "pub", topic, "ignition.msgs.Odometry", "10", "0", "pose { position { x: 1.5 } }",
        "--wait", "0",
    )  # fmt: skip


def string_peer(topic: str, text: str, hz: str = "10") -> PeerProcess:
    return start_peer(
        "pub", topic, "ignition.msgs.StringMsg", hz, "0", f'data: "{text}"', "--wait", "0"
    )


def test_auto_bridge_follows_real_fortress_peers(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    stem = unique_name("auto")  # /auto_<pid>_<hex>: nothing else in the partition has it
    odom_gz = f"{stem}/model/box::link/odometry"
    status_gz = f"{stem}/3d-status"
    denied_gz = f"{stem}/camera/denied"
    fortress_sub = f"{stem}/fortress_cmd"
    odom_ros, status_ros = f"{stem}/model/box/link/odometry", f"{stem}/_3d_status"
    bridge = start_process(
        bridge_command(
            ros_args=[
                "-p", "auto_bridge:=true",
                "-p", f"auto_bridge_allow:=[^{stem}/]",
                "-p", "auto_bridge_deny:=[/camera/]",
                "-p", "subscription_heartbeat:=200",
            ]
        )
    )  # fmt: skip
    started.append(bridge)
    wait_for_line(bridge, r"Following Gazebo discovery: auto_bridge", timeout=30)
    odometry = odometry_peer(odom_gz)
    started += [odometry, string_peer(status_gz, "hi"), string_peer(denied_gz, "no")]
    started.append(start_peer("echo", fortress_sub, "ignition.msgs.Twist", "60"))

    wait_until(lambda: {odom_ros, status_ros} <= set(ros_topics(probe)), WAIT, "both in ROS")
    assert ros_topics(probe)[odom_ros] == ["nav_msgs/msg/Odometry"]
    assert ros_topics(probe)[status_ros] == ["std_msgs/msg/String"]
    odoms, _ = probe.subscribe(Odometry, odom_ros)
    statuses, _ = probe.subscribe(String, status_ros)
    odoms.wait_for_count(1, WAIT)  # lazy: flows once ROS subscribes
    statuses.wait_for_count(1, WAIT)
    assert odoms.items()[0][0].pose.pose.position.x == 1.5
    assert statuses.items()[0][0].data == "hi"
    wait_for_line(bridge, rf"Gazebo {re.escape(odom_gz)} is bridged as ROS {odom_ros[1:]}")
    wait_for_line(bridge, rf"Not bridging Gazebo {fortress_sub}: its Gazebo subscribers announce")
    assert not any("denied" in name for name in ros_topics(probe))

    odometry.stop()  # the process says goodbye: its topic goes from ROS too
    wait_until(lambda: probe.count_publishers(odom_ros) == 0, WAIT, f"{odom_ros} gone from ROS")
    wait_for_line(bridge, rf"Removing the discovered bridge of Gazebo {re.escape(odom_gz)}")
    assert status_ros in ros_topics(probe)
    assert not any("denied" in name for name in ros_topics(probe))
    assert bridge.output().count(f"Not bridging Gazebo {fortress_sub}") == 1


def test_auto_bridge_over_zenoh_carries_values_both_ways(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    stem = unique_name("zauto")
    pose_gz, cmd_gz = f"{stem}/model/a::b/pose", f"{stem}/cmd_vel"
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    bridge = start_process(
        bridge_command(ros_args=["-p", "auto_bridge:=true", "-p", "subscription_heartbeat:=200"]),
        zenoh_env("peer", [endpoint], []),
    )
    started.append(bridge)
    wait_for_line(bridge, r"Following Gazebo discovery", timeout=30)
    spec = {
        "publish": [[pose_gz, "gz.msgs.Pose", "position { y: 2.5 }"]],
        "echo": [[cmd_gz, "gz.msgs.Twist"]],
        "seconds": 40,
    }
    gazebo = start_process(
        [sys.executable, str(GAZEBO_SIDE), json.dumps(spec)], zenoh_env("peer", [], [endpoint])
    )
    started.append(gazebo)
    wait_for_line(gazebo, r"^READY", timeout=30)
    pose_ros = f"{stem}/model/a/b/pose"
    wait_until(lambda: {pose_ros, cmd_gz} <= set(ros_topics(probe)), WAIT, "both topics in ROS")
    poses, _ = probe.subscribe(Pose, pose_ros)
    assert poses.wait_for_count(1, WAIT)[0][0].position.y == 2.5
    publisher = probe.run(lambda: probe.node.create_publisher(Twist, cmd_gz, 10))
    twist = Twist()
    twist.linear.x = 0.75
    publish_until(
        lambda _: probe.run(lambda: publisher.publish(twist)),
        lambda: any(line.startswith("MSG ") for line in gazebo.output().splitlines()),
        "the Twist reached the Gazebo subscriber",
    )
    assert re.search(r"MSG gz\.msgs\.Twist linear \{ x: 0\.75 \}", gazebo.output())
    gazebo.stop()
    wait_until(lambda: probe.count_publishers(pose_ros) == 0, WAIT, f"{pose_ros} gone from ROS")


def test_discover_prints_a_yaml_that_bridges_the_same_topics(
    probe: RosSide, started: list[PeerProcess], tmp_path: Path
) -> None:
    require_peer()
    stem = unique_name("disc")
    clock_gz, odom_gz = f"{stem}/clock", f"{stem}/model/r-1/odometry"
    started += [
        start_peer(
            "pub", clock_gz, "ignition.msgs.Clock", "10", "0", "sim { sec: 7 }", "--wait", "0"
        ),
        odometry_peer(odom_gz),
    ]
    discover = start_process(
        [str(PARAMETER_BRIDGE), "--discover", "3", "--ros-args",
         "-p", f"auto_bridge_allow:=[^{stem}/]"]
    )  # fmt: skip
    started.append(discover)
    assert discover.wait(30) == 0, discover.output()
    text = "\n".join(
        line for line in discover.output().splitlines() if not line.startswith("[")
    )  # the merged output: leave out the log lines (standard error)
    assert f'gz_topic_name: "{odom_gz}"' in text
    assert f'ros_topic_name: "{odom_gz[1:].replace("r-1", "r_1")}"' in text
    assert 'gz_type_name: "gz.msgs.Clock"' in text
    assert "direction: GZ_TO_ROS" in text
    config = tmp_path / "discovered.yaml"
    config.write_text(text + "\n")
    bridge = start_process(bridge_command(ros_args=["-p", f"config_file:={config}"]))
    started.append(bridge)
    odom_ros = f"{stem}/model/r_1/odometry"
    wait_until(lambda: {odom_ros, clock_gz} <= set(ros_topics(probe)), WAIT + 20, "the same topics")
    odoms, _ = probe.subscribe(Odometry, odom_ros)
    assert odoms.wait_for_count(1, WAIT)[0][0].pose.pose.position.x == 1.5
    assert "Following Gazebo discovery" not in bridge.output()


def twist_publisher(ros: RosSide, topic: str, x: float) -> Callable[[int], None]:
    """A ROS Twist publisher on ``topic``; the returned function publishes linear.x = ``x``."""
    publisher = ros.run(lambda: ros.node.create_publisher(Twist, topic, 10))
    twist = Twist()
    twist.linear.x = x
    return lambda _: ros.run(lambda: publisher.publish(twist))


def echoed(peer: PeerProcess, pattern: str) -> Callable[[], bool]:
    return lambda: re.search(pattern, peer.output()) is not None


def test_auto_bridge_types_a_fortress_subscriber_from_the_ros_publisher(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    stem = unique_name("infer")
    cmd_vel = f"{stem}/model/robot1/cmd_vel"
    bridge = start_process(
        bridge_command(ros_args=["-p", "auto_bridge:=true", "-p", f"auto_bridge_allow:=[^{stem}/]"])
    )
    started.append(bridge)
    wait_for_line(bridge, r"Following Gazebo discovery: auto_bridge", timeout=30)
    diff_drive = start_peer("echo", cmd_vel, "ignition.msgs.Twist", "60")  # as DiffDrive does
    started.append(diff_drive)
    wait_for_line(bridge, rf"Not bridging Gazebo {cmd_vel}: .*no ROS node publishes on")
    publish = twist_publisher(probe, cmd_vel, 0.75)
    wait_for_line(
        bridge,
        rf"Bridging ROS {cmd_vel[1:]} \(geometry_msgs/msg/Twist\) -> Gazebo {cmd_vel} "
        r"\(ignition\.msgs\.Twist\): .*inferred from the ROS publisher's type",
    )
    publish_until(publish, echoed(diff_drive, r"MSG ignition\.msgs\.Twist .*x: 0\.75"), "echoed")
    assert "Removing the discovered bridge" not in bridge.output()


def test_discover_writes_the_inferred_entry_and_the_file_carries_the_values(
    probe: RosSide, started: list[PeerProcess], tmp_path: Path
) -> None:
    require_peer()
    stem = unique_name("dinfer")
    cmd_vel = f"{stem}/model/robot1/cmd_vel"
    discover = start_process(
        [str(PARAMETER_BRIDGE), "--discover", "6", "--ros-args",
         "-p", f"auto_bridge_allow:=[^{stem}/]"]
    )  # fmt: skip
    started.append(discover)
    # A Fortress subscriber is heard only when it subscribes: after --discover listens.
    wait_for_line(discover, r"Listening to Gazebo discovery", timeout=30)
    diff_drive = start_peer("echo", cmd_vel, "ignition.msgs.Twist", "90")
    started.append(diff_drive)
    publish = twist_publisher(probe, cmd_vel, -1.25)
    assert discover.wait(30) == 0, discover.output()
    text = "\n".join(line for line in discover.output().splitlines() if not line.startswith("["))
    entry = text.split(f"# inferred: {cmd_vel}'s Gazebo subscribers tell no type", 1)[1]
    assert f'gz_topic_name: "{cmd_vel}"' in entry
    assert 'ros_type_name: "geometry_msgs/msg/Twist"' in entry
    assert 'gz_type_name: "gz.msgs.Twist"' in entry
    assert "direction: ROS_TO_GZ" in entry
    assert "1 entries (marked 'inferred') take their types from the ROS publisher" in text
    config = tmp_path / "discovered.yaml"
    config.write_text(text + "\n")
    # The Fortress subscriber predates this bridge: the entry's announcement makes it register.
    bridge = start_process(bridge_command(ros_args=["-p", f"config_file:={config}"]))
    started.append(bridge)
    wait_for_line(bridge, r"Creating ROS->GZ Bridge: \[", timeout=30)
    publish_until(publish, echoed(diff_drive, r"MSG ignition\.msgs\.Twist .*x: -1\.25"), "echoed")


def test_a_typed_gazebo_subscriber_wins_over_a_ros_publisher_of_another_type(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    stem = unique_name("typed")
    cmd_vel = f"{stem}/cmd_vel"
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    bridge = start_process(
        bridge_command(
            ros_args=["-p", "auto_bridge:=true", "-p", f"auto_bridge_allow:=[^{stem}/]"]
        ),
        zenoh_env("peer", [endpoint], []),
    )
    started.append(bridge)
    wait_for_line(bridge, r"Following Gazebo discovery: auto_bridge", timeout=30)
    text_publisher = probe.run(lambda: probe.node.create_publisher(String, cmd_vel, 10))
    # A subscriber that tells its type: Zenoh tokens always do. (Our ZeroMQ node's heartbeats
    # look like gz-transport 11/12's, so the bridge does not ask it for its subscriptions.)
    spec = {"echo": [[cmd_vel, "gz.msgs.Twist"]], "seconds": 60}
    gazebo = start_process(
        [sys.executable, str(GAZEBO_SIDE), json.dumps(spec)], zenoh_env("peer", [], [endpoint])
    )
    started.append(gazebo)
    wait_for_line(gazebo, r"^READY", timeout=30)
    wait_for_line(
        bridge,
        rf"Gazebo {cmd_vel}: the ROS publishers of {cmd_vel[1:]} use std_msgs/msg/String, which "
        r"does not pair with gz\.msgs\.Twist, the type its Gazebo subscribers take: the bridge "
        r"follows the Gazebo type \(geometry_msgs/msg/Twist <-> gz\.msgs\.Twist\)",
        timeout=30,
    )
    wait_for_line(
        bridge,
        r"uses std_msgs/msg/String, but the bridge took geometry_msgs/msg/Twist from discovery "
        r"\(typed Gazebo subscriber\); std_msgs/msg/String does not pair with gz\.msgs\.Twist",
        timeout=30,
    )
    probe.destroy(text_publisher)
    publish = twist_publisher(probe, cmd_vel, 2.5)
    publish_until(publish, echoed(gazebo, r"MSG gz\.msgs\.Twist linear \{ x: 2\.5 \}"), "echoed")


def test_a_fortress_subscriber_older_than_the_bridge_shows_only_when_its_type_is_announced(
    started: list[PeerProcess],
) -> None:
    require_peer()
    topic = f"{unique_name('old')}/cmd_vel"
    peer = start_peer("echo", topic, "ignition.msgs.Twist", "60")
    started.append(peer)
    wait_for_line(peer, r"^READY", timeout=30)
    with create_gz_node() as gz_node:  # a bridge that starts after the subscription

        def subscribers() -> list[str]:
            return [e.msg_type for e in gz_node.observe(topic) if e.role == SUBSCRIBER]

        # a publisher started later is heard; the older subscription is never re-announced
        witness = f"{topic}_witness"
        started.append(
            start_peer("pub", witness, "ignition.msgs.Twist", "10", "0", "", "--wait", "0")
        )
        wait_until(lambda: bool(gz_node.topic_info(witness)), WAIT, "the witness publisher")
        assert subscribers() == []
        publisher = gz_node.advertise(topic, "gz.msgs.Twist")  # both spellings announced
        wait_until(lambda: subscribers() == ["ignition.msgs.Twist"], WAIT, "it takes ours")
        publisher.close()


def test_check_with_auto_bridge_checks_the_inferred_entry_and_names_its_rule(
    probe: RosSide, started: list[PeerProcess]
) -> None:
    require_peer()
    stem = unique_name("cinfer")
    cmd_vel = f"{stem}/model/robot1/cmd_vel"
    # the ROS publisher before the check, the Gazebo subscriber after "Listening" (one older
    # than the bridge shows only once its type is announced, test above); both must be known
    # half-way through the window, when the check asks for the discovered entries: in a full
    # suite on a busy machine the C++ peer's start took more than the 3 s of a 6 s window
    twist_publisher(probe, cmd_vel, 1.0)
    check = start_process(
        [str(PARAMETER_BRIDGE), "--check", str(CHECK_WINDOW), "--ros-args",
         "-p", "auto_bridge:=true", "-p", f"auto_bridge_allow:=[^{stem}/]"]
    )  # fmt: skip
    started.append(check)
    wait_for_line(check, rf"^Listening for {CHECK_WINDOW} s", timeout=30)
    listening = time.monotonic()
    echo = start_peer("echo", cmd_vel, "ignition.msgs.Twist", "60")
    started.append(echo)
    wait_for_line(echo, r"^READY", timeout=30)
    subscribed_after = time.monotonic() - listening
    assert subscribed_after < CHECK_WINDOW / 2, (
        f"the Gazebo peer subscribed {subscribed_after:.1f} s into the window, after the check "
        "asked for discovered entries: this test needs a less loaded machine"
    )
    assert check.wait(30) == 0, check.output()
    title = (
        f"ROS {cmd_vel} (geometry_msgs/msg/Twist) -> Gazebo {cmd_vel} (ignition.msgs.Twist) "
        "(auto_bridge, discovered: inferred from the ROS publisher's type)"
    )
    output = check.output()
    assert title in output, output
    report = output.split(title, 1)[1]
    assert "Gazebo: subscriber (ignition.msgs.Twist, takes ours)" in report
    assert "ok: messages can flow" in report


def test_entries_discovery_completes_are_named_at_start_and_by_check(
    started: list[PeerProcess], tmp_path: Path
) -> None:
    """The start-up line said '1 YAML entries completed by discovery', naming none, and
    --check left such an entry out of its report without a word."""
    topic = unique_name("left_out_type")
    config = tmp_path / "bridge.yaml"
    config.write_text(
        f"- topic_name: {topic}\n  ros_type_name: std_msgs/msg/String\n"
        "  gz_typename: gz.msgs.StringMsg\n"
    )
    where = f"{config} entry 1 (line 1)"
    bridge = start_process(bridge_command(ros_args=["-p", f"config_file:={config}"]))
    started.append(bridge)
    wait_for_line(
        bridge,
        "without gz_type_name the entry waits for Gazebo discovery to give its types",
        timeout=30,
    )
    wait_for_line(
        bridge,
        re.escape(f"Following Gazebo discovery: 1 YAML entry completed by discovery ({where})"),
        timeout=30,
    )
    check = start_process(
        [str(PARAMETER_BRIDGE), "--check", "1", "--ros-args", "-p", f"config_file:={config}"]
    )
    started.append(check)
    check.wait(30)
    assert (
        f"{where}: completed by Gazebo discovery (a type left out, or a wildcard): checked as "
        "the topics it takes"
    ) in check.output()
