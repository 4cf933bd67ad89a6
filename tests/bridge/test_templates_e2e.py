"""Templates in the YAML (issue 16, point 3), with real Fortress peers (the C++ ``ign_peer``).

One entry ``/model/${robot}/odometry`` with ``robot=r1,r2`` (the ``placeholders`` parameter)
bridges both robots' odometry into each robot's own ROS namespace, in one process. A wildcard
entry with a type picks up a ``cmd_vel`` whose Fortress subscriber appears after the bridge
started (Fortress subscribers announce no type: the entry gives it), and ROS messages reach it.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from testing.behaviour_harness import (
    WAIT,
    RosSide,
    bridge_command,
    probe,
    publish_until,
    started,
)
from testing.gzpeer import (
    PeerProcess,
    require_peer,
    start_peer,
    start_process,
    unique_name,
    wait_for_line,
    wait_until,
)

__all__ = ["probe", "started"]

pytestmark = [pytest.mark.ros, pytest.mark.peer]


def test_one_templated_entry_bridges_two_robots_and_a_wildcard_takes_a_late_topic(
    probe: RosSide, started: list[PeerProcess], tmp_path: Path
) -> None:
    require_peer()
    stem = unique_name("tpl")
    config = tmp_path / "robots.yaml"
    config.write_text(
        f"- gz_topic_name: {stem}/model/${{robot}}/odometry\n"
        f"  ros_topic_name: {stem}/${{robot}}/odom\n"
        "  ros_type_name: nav_msgs/msg/Odometry\n"
        "  gz_type_name: gz.msgs.Odometry\n"
        "  direction: GZ_TO_ROS\n"
        f"- gz_topic_name: {stem}/late/*/cmd_vel\n"
        f"  ros_topic_name: {stem}/*/cmd_vel\n"
        "  gz_type_name: gz.msgs.Twist\n"
    )
    for robot, x in (("r1", 1.0), ("r2", 2.0)):
        started.append(
            start_peer(
                "pub", f"{stem}/model/{robot}/odometry", "ignition.msgs.Odometry", "10", "0",
                f"pose {{ position {{ x: {x} }} }}", "--wait", "0",
            )
        )  # fmt: skip
    bridge = start_process(
        bridge_command(
            ros_args=["-p", f"config_file:={config}", "-p", "placeholders:=[robot=r1, robot=r2]"]
        )
    )
    started.append(bridge)
    wait_for_line(
        bridge, r"Following Gazebo discovery: 1 YAML entry completed by discovery", timeout=30
    )
    for robot, x in (("r1", 1.0), ("r2", 2.0)):
        inbox, _ = probe.subscribe(Odometry, f"{stem}/{robot}/odom")
        odometry = inbox.wait_for_count(1, WAIT)[0][0]
        assert odometry.pose.pose.position.x == x

    cmd_gz, cmd_ros = f"{stem}/late/robot_3/cmd_vel", f"{stem}/robot_3/cmd_vel"
    echo = start_peer("echo", cmd_gz, "ignition.msgs.Twist", "60")
    started.append(echo)
    wait_for_line(echo, r"^READY")
    wait_until(lambda: probe.count_subscribers(cmd_ros) == 1, WAIT, f"the bridge on {cmd_ros}")
    publisher = probe.run(lambda: probe.node.create_publisher(Twist, cmd_ros, 10))
    twist = Twist()
    twist.angular.z = 0.5
    publish_until(
        lambda _: probe.run(lambda: publisher.publish(twist)),
        lambda: "MSG " in echo.output(),
        "the Twist reached the Fortress subscriber",
    )
    assert re.search(r"MSG ignition\.msgs\.Twist .*angular \{\s*z: 0\.5", echo.output())
